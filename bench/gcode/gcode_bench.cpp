// SPDX-License-Identifier: GPL-3.0-or-later
// Interpreter throughput (lines/s): scan into a canon::Program, canon text, bare interpreter.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>
#include <string>

#include <unistd.h>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/canon/rs274_printer.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

namespace {

using namespace opencnc;

// The same shape as bench/gcode/gen_program.py: "G1 X.. Y.. Z.." lines (seeded, so every
// run reads the same bytes), written to a temporary file that the interpreter streams.
class ProgramFile {
 public:
  explicit ProgramFile(int lines) {
    char name[] = "/tmp/opencnc_gcode_bench_XXXXXX";
    const int fd = ::mkstemp(name);
    path_ = name;
    std::FILE* f = ::fdopen(fd, "w");
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> xy(-500, 500), z(-50, 0);
    std::fprintf(f, "G21 G90 G17 F1500\n");
    for (int i = 0; i < lines; ++i) std::fprintf(f, "G1 X%.3f Y%.3f Z%.3f\n", xy(rng), xy(rng), z(rng));
    std::fprintf(f, "M2\n");
    std::fclose(f);
  }
  ~ProgramFile() { ::unlink(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

const ProgramFile& program_file() {
  static const ProgramFile file(200000);
  return file;
}

template <typename MakeSink>
void run_program(benchmark::State& state, MakeSink make_sink) {
  const std::string& path = program_file().path();
  const auto extensions = gcode::standard_extensions(gcode::Dialect::LinuxCnc);
  std::uint64_t blocks = 0;
  for (auto _ : state) {
    gcode::Options options;
    options.mode = gcode::Mode::Scan;
    options.extensions = extensions;   // the modules `opencnc scan` and `opencnc canon` run with
    gcode::Interpreter interp(options);
    if (!interp.open(path)) state.SkipWithError("cannot open the program");
    auto sink = make_sink();
    if (interp.run(*sink) != gcode::RunStatus::Finished) state.SkipWithError("the program did not finish");
    blocks = interp.state().blocks_executed;
    benchmark::DoNotOptimize(sink.get());
  }
  state.counters["lines/s"] = benchmark::Counter(static_cast<double>(blocks), benchmark::Counter::kIsIterationInvariantRate);
}

// Scan mode as `opencnc scan` uses it: the whole program built into a canon::Program.
void BM_ScanToProgram(benchmark::State& state) {
  run_program(state, [] { return std::make_unique<canon::ProgramBuilder>(kXyzabc); });
}
BENCHMARK(BM_ScanToProgram)->Unit(benchmark::kMillisecond);

// The interpreter alone: canonical calls go to a sink that ignores them.
void BM_InterpretOnly(benchmark::State& state) {
  run_program(state, [] { return std::make_unique<canon::Sink>(); });
}
BENCHMARK(BM_InterpretOnly)->Unit(benchmark::kMillisecond);

// `opencnc canon`: rs274's text format written to /dev/null.
void BM_CanonText(benchmark::State& state) {
  std::FILE* null = std::fopen("/dev/null", "w");
  run_program(state, [null] { return std::make_unique<canon::Rs274Printer>(null); });
  std::fclose(null);
}
BENCHMARK(BM_CanonText)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
