// SPDX-License-Identifier: GPL-3.0-or-later
// Cutter compensation throughput: a long contour of lines and arcs interpreted with and
// without G41, so the difference is the compensation stage (corners, queue, state).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <unistd.h>

#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

namespace {

using namespace opencnc;

// 200,000 moves round a wavy ring (every fourth one an arc), all corners well clear of a
// gouge, written to a temporary file; `comp` adds G41.1 D2 before the first move.
class ContourFile {
 public:
  explicit ContourFile(bool comp) {
    char name[] = "/tmp/opencnc_comp_bench_XXXXXX";
    const int fd = ::mkstemp(name);
    path_ = name;
    std::FILE* f = ::fdopen(fd, "w");
    std::fprintf(f, "G21 G90 G17 F1500\nG0 X0 Y0\n%s", comp ? "G41.1 D2\n" : "");
    constexpr int kMoves = 200000, kPerTurn = 400;
    for (int i = 0; i < kMoves; ++i) {
      const double a = 2 * 3.14159265358979 * (i % kPerTurn) / kPerTurn;
      const double r = 200 + 20 * std::sin(7 * a);
      if (i % 4 == 3)
        std::fprintf(f, "G3 X%.4f Y%.4f R%.4f\n", r * std::cos(a), r * std::sin(a), 150.0);
      else
        std::fprintf(f, "G1 X%.4f Y%.4f\n", r * std::cos(a), r * std::sin(a));
    }
    std::fprintf(f, "%sM2\n", comp ? "G40 G1 X0 Y0\n" : "");
    std::fclose(f);
  }
  ~ContourFile() { ::unlink(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

void run_contour(benchmark::State& state, bool comp) {
  static const ContourFile plain(false), compensated(true);
  const std::string& path = comp ? compensated.path() : plain.path();
  gcode::Options options;
  options.extensions = gcode::standard_extensions(gcode::Dialect::LinuxCnc);
  std::uint64_t blocks = 0;
  for (auto _ : state) {
    gcode::Interpreter interp(options);
    if (!interp.open(path)) state.SkipWithError("cannot open the program");
    canon::Sink sink;
    if (interp.run(sink) != gcode::RunStatus::Finished) state.SkipWithError("the program did not finish");
    blocks = interp.state().blocks_executed;
  }
  state.counters["lines/s"] =
      benchmark::Counter(static_cast<double>(blocks), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_ContourPlain(benchmark::State& state) {
  run_contour(state, false);
}
BENCHMARK(BM_ContourPlain)->Unit(benchmark::kMillisecond);

void BM_ContourCompensated(benchmark::State& state) {
  run_contour(state, true);
}
BENCHMARK(BM_ContourCompensated)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
