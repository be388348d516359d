// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of one servo period of the simulated machine (write + read) for 3, 6 and 9 joints, with
// and without whole periods, and of mill-3axis moving and standing.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "opencnc/machine/sim_machine.hpp"

namespace {

using namespace opencnc::machine;

// Every feature that costs something is on: friction, backlash, a pitch table, table
// feedback on every other joint, index marks, four noisy switches per joint, the spindle.
// `linear_periods` off: every sub-step one by one.
SimMachineConfig bench_config(int joints, int substeps, bool linear_periods) {
  SimMachineConfig c;
  c.joint_count = joints;
  c.substeps = substeps;
  c.linear_periods = linear_periods;
  for (int j = 0; j < joints; ++j) {
    SimJointConfig& jc = c.joints[static_cast<std::size_t>(j)];
    jc.counts_per_unit = 13107.2;
    jc.model.backlash = 0.004;
    for (int p = 0; p <= 10; ++p) jc.model.pitch_error.push_back({-500.0 + 100.0 * p, 0.002 * std::sin(p)});
    jc.model.feedback = j % 2 ? FeedbackSource::Table : FeedbackSource::Motor;
    jc.model.index_spacing = 10;
    jc.switches.limit_neg = {true, -kInf, -490};
    jc.switches.limit_pos = {true, 490, kInf};
    jc.switches.home = {true, 480, kInf};
    jc.switches.decel = {true, 470, 485};
  }
  c.spindle = true;
  c.spindle_config.max_rpm = 8000;
  c.spindle_config.encoder_counts_per_rev = 4096;
  return c;
}

/// A second of circles at 100 mm/s on every joint, one output image per period.
std::vector<MachineOutputs> trajectory(int joints) {
  std::vector<MachineOutputs> outs(1000);
  for (int k = 0; k < 1000; ++k) {
    MachineOutputs& o = outs[static_cast<std::size_t>(k)];
    o.estop_release = true;
    o.spindle = {3000, SpindleDirection::Clockwise};
    const double w = 2 * 3.141592653589793;  // 1 Hz, radius 100/2π mm
    for (int j = 0; j < joints; ++j) {
      const double phase = w * k * 0.001 + j;
      o.joints[static_cast<std::size_t>(j)] = {100 / w * std::sin(phase), 100 * std::cos(phase), 0, true};
    }
  }
  return outs;
}

// mill-3axis as shipped: motor encoders, no backlash or pitch table, two limit switches per
// axis, the spindle. Its drives run whole periods at once while they move one way or stand.
SimMachineConfig mill_config(bool linear_periods) {
  SimMachineConfig c;
  c.joint_count = 3;
  c.linear_periods = linear_periods;
  const double mass[] = {150, 250, 120}, coulomb[] = {40, 60, 50}, stiction[] = {50, 75, 65};
  for (std::size_t j = 0; j < 3; ++j) {
    SimJointConfig& jc = c.joints[j];
    jc.counts_per_unit = 13107.2;
    jc.model.inertia = mass[j];
    jc.model.peak_effort = 4000;
    jc.model.coulomb_friction = coulomb[j];
    jc.model.static_friction = stiction[j];
    jc.switches.limit_neg = {true, -kInf, -2002};
    jc.switches.limit_pos = {true, 2002, kInf};
    jc.switches.hysteresis = 0.02;
    jc.switches.noise = 0.003;
  }
  c.spindle = true;
  c.spindle_config.max_rpm = 8000;
  c.spindle_config.encoder_counts_per_rev = 4096;
  return c;
}

void run_periods(benchmark::State& state, SimMachine& machine, const std::vector<MachineOutputs>& outs) {
  MachineInputs in;
  std::size_t k = 0;
  for (auto _ : state) {
    machine.read(in);
    benchmark::DoNotOptimize(in);
    machine.write(outs[k]);
    k = k + 1 == outs.size() ? 0 : k + 1;
  }
}

void BM_SimMachinePeriod(benchmark::State& state) {
  const int joints = static_cast<int>(state.range(0));
  const int substeps = static_cast<int>(state.range(1));
  SimMachine machine(bench_config(joints, substeps, state.range(2) != 0));
  run_periods(state, machine, trajectory(joints));
  state.counters["joints"] = joints;
  state.counters["substeps"] = substeps;
}
BENCHMARK(BM_SimMachinePeriod)
    ->ArgNames({"joints", "substeps", "linear"})
    ->Args({3, 10, 0})
    ->Args({3, 10, 1})
    ->Args({6, 10, 0})
    ->Args({6, 10, 1})
    ->Args({9, 10, 1})
    ->Args({6, 5, 1})
    ->Args({6, 20, 1});

// Circles at 100 mm/s (range 0) or standing still (range 1) on mill-3axis.
void BM_MillPeriod(benchmark::State& state) {
  SimMachine machine(mill_config(state.range(1) != 0));
  std::vector<MachineOutputs> outs = trajectory(3);
  if (state.range(0) == 1) {
    for (MachineOutputs& o : outs) {
      o = outs.front();
      for (JointOutputs& j : o.joints) j.velocity_ff = 0;
    }
  }
  run_periods(state, machine, outs);
}
BENCHMARK(BM_MillPeriod)
    ->ArgNames({"still", "linear"})
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1});

}  // namespace
