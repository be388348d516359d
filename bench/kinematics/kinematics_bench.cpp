// SPDX-License-Identifier: GPL-3.0-or-later
// kinematics_bench — the cost of one forward transform, one inverse (both branches, the nearest
// taken) and one Jacobian per structure: what the kinematics stage adds to a servo period.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>

#include "opencnc/kinematics/kinematics.hpp"

using namespace opencnc;
using namespace opencnc::kinematics;

namespace {

Config trunnion() {
  Config c{Structure::TableTable,
           {RotaryAxis{Axis::A, {1, 0, 0}, {0, 12.5, -80}}, RotaryAxis{Axis::C, {0, 0, 1}, {3.2, 11.9, 0}}}};
  prepare(c);
  return c;
}

Config head_table() {
  Config c{Structure::HeadTable,
           {RotaryAxis{Axis::B, {0, 1, 0}, {0, 0, 120}}, RotaryAxis{Axis::C, {0, 0, 1}, {250, 180, 0}}}};
  prepare(c);
  return c;
}

/// A servo period's worth of motion: the pose moves a little every call, as it does along a path.
Pose pose_at(int n) {
  Pose j{};
  j[0] = 10 + 1e-3 * n;
  j[1] = -20;
  j[2] = 35;
  j[index(Axis::A)] = 20 + 1e-4 * n;
  j[index(Axis::B)] = 20 + 1e-4 * n;
  j[index(Axis::C)] = 40 + 1e-3 * n;
  return j;
}

void forward_cost(benchmark::State& state, const Config& c) {
  int n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(forward(c, pose_at(++n & 1023), 120));
}

void inverse_cost(benchmark::State& state, const Config& c) {
  std::array<ToolPose, 1024> tools{};
  for (int n = 0; n < 1024; ++n) tools[static_cast<std::size_t>(n)] = forward(c, pose_at(n), 120);
  int n = 0;
  Pose from = pose_at(0);
  for (auto _ : state) {
    const Inverse j = inverse(c, tools[static_cast<std::size_t>(++n & 1023)], 120, from);
    benchmark::DoNotOptimize(j);
    from = j.joints;
  }
}

void jacobian_cost(benchmark::State& state, const Config& c) {
  int n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(jacobian(c, pose_at(++n & 1023), 120));
}

}  // namespace

BENCHMARK_CAPTURE(forward_cost, trunnion, trunnion());
BENCHMARK_CAPTURE(inverse_cost, trunnion, trunnion());
BENCHMARK_CAPTURE(jacobian_cost, trunnion, trunnion());
BENCHMARK_CAPTURE(forward_cost, head_table, head_table());
BENCHMARK_CAPTURE(inverse_cost, head_table, head_table());
BENCHMARK_CAPTURE(jacobian_cost, head_table, head_table());
BENCHMARK_MAIN();
