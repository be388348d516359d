// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of one servo period of the simulated machine (write + read) for 3, 6 and 9 joints.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "opencnc/machine/sim_machine.hpp"

namespace {

using namespace opencnc::machine;

// Every feature that costs something is on: friction, backlash, a pitch table, table
// feedback on every other joint, index marks, four noisy switches per joint, the spindle.
SimMachineConfig bench_config(int joints, int substeps) {
  SimMachineConfig c;
  c.joint_count = joints;
  c.substeps = substeps;
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

void BM_SimMachinePeriod(benchmark::State& state) {
  const int joints = static_cast<int>(state.range(0));
  const int substeps = static_cast<int>(state.range(1));
  SimMachine machine(bench_config(joints, substeps));
  const std::vector<MachineOutputs> outs = trajectory(joints);
  MachineInputs in;
  std::size_t k = 0;
  for (auto _ : state) {
    machine.read(in);
    benchmark::DoNotOptimize(in);
    machine.write(outs[k]);
    k = k + 1 == outs.size() ? 0 : k + 1;
  }
  state.counters["joints"] = joints;
  state.counters["substeps"] = substeps;
}
BENCHMARK(BM_SimMachinePeriod)->Args({3, 10})->Args({6, 10})->Args({9, 10})->Args({6, 5})->Args({6, 20});

}  // namespace
