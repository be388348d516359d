// SPDX-License-Identifier: GPL-3.0-or-later
// plan_run — motion time and trace metrics of the reference programs (or of `rs274 -g` listings
// with --canon) in virtual time, and the CPU time that took (NOCHECK=1: without the checker).
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include <fmt/format.h>

#include <fstream>

#include "opencnc/analysis/reference_programs.hpp"
#include "opencnc/analysis/simulate.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "rs274_canon.hpp"

using namespace opencnc;

namespace {

std::string g_only;

/// CPU time of this thread: the machine is shared, so wall time says little about our cost.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void run(const std::string& name, const canon::Program& p, const plan::MachineLimits& lim) {
  if (!g_only.empty() && name.find(g_only) == std::string::npos) return;
  analysis::SimulationOptions opt;
  opt.check = std::getenv("NOCHECK") == nullptr;
  opt.max_time_s = 24 * 3600;
  const double t0 = cpu_seconds();
  const analysis::SimulationResult r = analysis::simulate(p, lim, opt);
  const double cpu = cpu_seconds() - t0;
  fmt::print(
      "{:28} motion {:9.3f} s  finished {}  blocks {}  blends {}  merged {}  cpu {:.3f} s ({:.0f}x real "
      "time)\n  {}\n",
      name, r.motion_time_s, r.finished, r.plan.blocks, r.plan.blends, r.plan.merged_moves, cpu,
      r.motion_time_s / cpu, r.report.summary());
  for (const auto& d : r.diagnostics.items()) fmt::print("  {}\n", d.format());
}

}  // namespace

int main(int argc, char** argv) {
  const plan::MachineLimits lim = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);
  if (argc > 2 && std::string(argv[1]) == "--canon") {
    // plan_run --canon LISTING...: each file is the output of `rs274 -g PROGRAM`.
    for (int i = 2; i < argc; ++i) {
      std::ifstream in(argv[i]);
      canon::ProgramBuilder b(kXyzabc);
      bench::read_rs274_listing(in, b);
      run(argv[i], b.take(), plan::MachineLimits::uniform(kXyzabc, 100, 1000));
    }
    return 0;
  }
  if (argc > 1) g_only = argv[1];
  using analysis::PathMode;
  const PathMode g64{canon::MotionControl::Continuous, 0.01, 0.01};
  const PathMode g64q0{canon::MotionControl::Continuous, 0.01, 0};
  const PathMode g61{canon::MotionControl::ExactPath, 0, 0};  // LinuxCNC prints G61 as CANON_EXACT_PATH
  run("square G61", analysis::square_program(100, 6000, g61), lim);
  run("square G64 P0.01", analysis::square_program(100, 6000, g64), lim);
  run("spiral 20k G64 P0.01", analysis::spiral_program(20000, 6000, g64), lim);
  run("spiral 20k G64 P0.01 Q0", analysis::spiral_program(20000, 6000, g64q0), lim);
  run("small arcs 90deg G64 P0.1",
      analysis::small_arcs_program(2000, 0.3, 90, 3000, {canon::MotionControl::Continuous, 0.1, 0.1}), lim);
  run("small arcs 180deg G64 P0.1",
      analysis::small_arcs_program(2000, 0.3, 180, 3000, {canon::MotionControl::Continuous, 0.1, 0.1}), lim);
  const plan::MachineLimits jl = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);
  run("jerk square G61", analysis::square_program(100, 6000, g61), jl);
  run("jerk square G64 P0.01", analysis::square_program(100, 6000, g64), jl);
  run("jerk spiral 20k G64 P0.01", analysis::spiral_program(20000, 6000, g64), jl);
  run("jerk spiral 20k G64 P0.01 Q0", analysis::spiral_program(20000, 6000, g64q0), jl);
  run("jerk small arcs 90deg G64 P0.1",
      analysis::small_arcs_program(2000, 0.3, 90, 3000, {canon::MotionControl::Continuous, 0.1, 0.1}), jl);
  return 0;
}
