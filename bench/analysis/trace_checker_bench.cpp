// SPDX-License-Identifier: GPL-3.0-or-later
// TraceChecker::add on a helix of N turns (issue 7: `G2 X0 Y0 Z-1 I5 J0 P100` at F3000 took 30 s of
// checking for 63 s of machining, P1000 did not finish in a minute): the time per servo sample
// must not grow with the number of turns.
//   build/bench/analysis/trace_checker_bench
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "opencnc/analysis/trace_checker.hpp"
#include "opencnc/canon/program_builder.hpp"

namespace {

using namespace opencnc;

constexpr double kRadius = 5, kDepth = 1;

/// The helix: from (10, 0, 0) about (5, 0) clockwise, `turns` turns down to Z -1.
canon::Program helix(int turns) {
  canon::ProgramBuilder b(kXyzabc);
  b.set_feed_rate(3000);
  Pose start;
  start[Axis::X] = 2 * kRadius;
  b.straight_traverse(0, start);
  canon::ArcFeed a;
  a.first_end = 2 * kRadius;
  a.second_end = 0;
  a.first_center = kRadius;
  a.second_center = 0;
  a.rotation = -turns;
  a.axis_end = -kDepth;
  a.end = start;
  a.end[Axis::Z] = -kDepth;
  b.arc_feed(1, a);
  return b.take();
}

/// Samples along the helix, 1 ms apart at F3000 (50 mm/s), slightly off the path as a drive is.
std::vector<Pose> samples(int turns, std::size_t count) {
  std::vector<Pose> out;
  const double length = 2 * std::numbers::pi * kRadius * turns;
  for (std::size_t k = 0; k < count; ++k) {
    const double s = std::fmod(0.05 * static_cast<double>(k), length);
    const double angle = -s / kRadius;
    const double r = kRadius + 0.001 * std::sin(0.1 * static_cast<double>(k));
    Pose p;
    p[Axis::X] = kRadius + r * std::cos(angle);
    p[Axis::Y] = r * std::sin(angle);
    p[Axis::Z] = -kDepth * s / length;
    out.push_back(p);
  }
  return out;
}

void BM_ContourCheckOnAHelix(benchmark::State& state) {
  const int turns = static_cast<int>(state.range(0));
  const canon::Program program = helix(turns);
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 0);
  const std::vector<Pose> points = samples(turns, 4096);
  std::size_t k = 0;
  analysis::TraceChecker checker(program, limits, 1e-3);
  for (auto _ : state) {
    checker.add(points[k], 1, 1);
    k = (k + 1) % points.size();
  }
  benchmark::DoNotOptimize(checker.report().max_contour_error_mm);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["max_contour_error_um"] = 1000 * checker.report().max_contour_error_mm;
}
BENCHMARK(BM_ContourCheckOnAHelix)->Arg(1)->Arg(10)->Arg(100)->Arg(1000);

}  // namespace

BENCHMARK_MAIN();
