// SPDX-License-Identifier: GPL-3.0-or-later
// Canned-cycle expansion throughput: cycle blocks and the moves they expand to, per second.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

namespace {

using namespace opencnc;

// Counts the motions a run emits.
class CountingSink : public canon::Sink {
 public:
  void straight_traverse(canon::SegmentId, const Pose&) override { ++moves; }
  void straight_feed(canon::SegmentId, const Pose&) override { ++moves; }
  std::uint64_t moves = 0;
};

// A grid of peck-drilled holes (G83, six pecks each) and rows of G91 drilled holes (G81 L10).
std::string program(int rows) {
  std::string p = "G21 G90 G17 F300\nG0 Z20\n";
  char line[160];
  for (int r = 0; r < rows; ++r) {
    std::snprintf(line, sizeof line, "G98 G83 X0 Y%d Z-12 R2 Q2\n", r * 10);
    p += line;
    for (int c = 1; c < 10; ++c) {
      std::snprintf(line, sizeof line, "X%d\n", c * 10);
      p += line;
    }
    std::snprintf(line, sizeof line, "G99 G91 G81 X10 Y0.5 R-18 Z-5 L10\nG90 G80\n");
    p += line;
  }
  return p + "M2\n";
}

void BM_CannedCycles(benchmark::State& state) {
  const std::string text = program(static_cast<int>(state.range(0)));
  std::uint64_t blocks = 0, moves = 0;
  for (auto _ : state) {
    gcode::Options options;
    options.extensions = gcode::standard_extensions(gcode::Dialect::LinuxCnc);
    gcode::Interpreter interp(options);
    interp.open_text("cycles.ngc", text);
    CountingSink sink;
    if (interp.run(sink) != gcode::RunStatus::Finished) state.SkipWithError("the program did not finish");
    blocks = interp.state().blocks_executed;
    moves = sink.moves;
  }
  state.counters["blocks/s"] = benchmark::Counter(static_cast<double>(blocks), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["moves/s"] = benchmark::Counter(static_cast<double>(moves), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_CannedCycles)->Arg(2000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
