// SPDX-License-Identifier: GPL-3.0-or-later
// traj_tick_bench — time of Interpolator::tick() for six axes, per tick, with percentiles.
// Each iteration is one tick timed on its own (manual time); planning between ticks is not timed.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/traj/interpolator.hpp"

using namespace opencnc;

namespace {

/// Six axes moving together: an XY spiral of 0.2–1 mm lines and arcs, Z waving, A B C turning.
canon::Program six_axis_program() {
  canon::ProgramBuilder b(kXyzabc);
  b.set_motion_control_mode(canon::MotionControl::Continuous, 0.01);
  b.set_feed_rate(3000);
  canon::SegmentId id = 0;
  double th = 0;
  for (int i = 0; i < 20000; ++i) {
    const double r = 40 + 10 * std::sin(i * 0.001);
    th += (0.2 + 0.8 * ((i * 7919) % 100) / 100.0) / r;
    Pose p;
    p[Axis::X] = r * std::cos(th);
    p[Axis::Y] = r * std::sin(th);
    p[Axis::Z] = 2 * std::sin(th * 3);
    p[Axis::A] = 10 * std::sin(th);
    p[Axis::B] = 5 * std::cos(th * 2);
    p[Axis::C] = th * 10;
    if (i % 50 == 25) {
      canon::ArcFeed a;  // a helical arc now and then (the end on the circle around the origin)
      a.plane = canon::Plane::XY;
      const Pose s = b.position();
      const double rs = std::hypot(s[0], s[1]), as = std::atan2(s[1], s[0]) + 0.02;
      a.first_end = rs * std::cos(as);
      a.second_end = rs * std::sin(as);
      a.first_center = 0;
      a.second_center = 0;
      a.rotation = 1;
      a.end = s;
      a.end[Axis::X] = a.first_end;
      a.end[Axis::Y] = a.second_end;
      a.end[Axis::Z] = s[2] + 0.01;
      a.axis_end = a.end[Axis::Z];
      b.arc_feed(id++, a);
      th = as;
      continue;
    }
    b.straight_feed(id++, p);
  }
  b.program_end();
  return b.take();
}

void tick_bench(benchmark::State& state, double jerk) {
  const canon::Program program = six_axis_program();
  plan::MachineLimits limits = plan::MachineLimits::uniform(kXyzabc, 100, 1000, jerk);
  auto queue = std::make_unique<traj::BlockQueue>();
  auto planner = std::make_unique<plan::Planner>(limits);
  planner->start(program);
  auto interp = std::make_unique<traj::Interpolator>(*queue, planner->interpolator_config(), program.start());
  traj::TickInput in;
  traj::TickOutput out;
  std::vector<double> ns;
  ns.reserve(1 << 22);
  std::uint64_t n = 0;
  for (auto _ : state) {
    planner->pump(*queue);
    in.feed_override = (n / 3000) % 4 == 3 ? 0.7 : 1.0;  // an override change now and then
    const auto t0 = std::chrono::steady_clock::now();
    interp->tick(in, out);
    const auto t1 = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(t1 - t0).count();
    state.SetIterationTime(dt);
    if (ns.size() < ns.capacity()) ns.push_back(dt * 1e9);
    ++n;
    if (out.state == traj::RunState::Finished) {  // start over (not timed: the tick above is)
      queue->reset();
      planner = std::make_unique<plan::Planner>(limits);
      planner->start(program);
      interp->restart(program.start());
    }
  }
  std::sort(ns.begin(), ns.end());
  const auto pct = [&](double q) {
    return ns.empty() ? 0.0 : ns[static_cast<std::size_t>(q * (ns.size() - 1))];
  };
  state.counters["p50_ns"] = pct(0.50);
  state.counters["p99_ns"] = pct(0.99);
  state.counters["p999_ns"] = pct(0.999);
  state.counters["max_ns"] = ns.empty() ? 0.0 : ns.back();
}

void BM_Tick6Axes(benchmark::State& state) {
  tick_bench(state, 0);
}
void BM_Tick6AxesJerkLimited(benchmark::State& state) {
  tick_bench(state, 1e5);
}

}  // namespace

BENCHMARK(BM_Tick6Axes)->UseManualTime()->Iterations(200000);
BENCHMARK(BM_Tick6AxesJerkLimited)->UseManualTime()->Iterations(200000);

BENCHMARK_MAIN();
