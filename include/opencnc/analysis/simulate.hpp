// SPDX-License-Identifier: GPL-3.0-or-later
// simulate() — runs a program through the planner and the interpolator in virtual time and
// measures the commanded trajectory (for tests, benchmarks and run reports).
#pragma once

#include <cstdint>
#include <functional>

#include "opencnc/analysis/trace_checker.hpp"
#include "opencnc/canon/program.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/plan/machine_limits.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/traj/interpolator.hpp"

namespace opencnc::analysis {

struct SimulationOptions {
  plan::PlannerConfig planner;
  double max_time_s = 7200;  ///< give up after this much virtual time
  bool check = true;         ///< run the TraceChecker on every sample
  /// Stand in for the rest of the controller: acknowledge Sync markers and program stops at once,
  /// and give the spindle the programmed speed as soon as S/M3/M4/M5 pass (an ideal spindle).
  /// The `inputs` hook runs after this and may override it.
  bool ideal_controller = true;
  /// Sets the inputs of tick `n` (overrides, feed hold, cycle start, spindle, ...). Optional.
  std::function<void(std::uint64_t n, const traj::TickOutput& previous, traj::TickInput& in)> inputs;
  /// Sees every tick's output. Optional.
  std::function<void(std::uint64_t n, const traj::TickOutput& out)> observe;
};

struct SimulationResult {
  bool finished = false;  ///< the program end was reached
  traj::RunState state = traj::RunState::Idle;
  std::uint64_t ticks = 0;
  /// From the first to the last period in which the commanded position changed (what LinuxCNC's
  /// harness calls the motion time).
  double motion_time_s = 0;
  TraceReport report;  ///< when options.check
  plan::PlanStats plan;
  Diagnostics diagnostics;  ///< planner errors, if it refused the program
};

/// Plans `program` for a machine with `limits` and runs it tick by tick, pumping the planner
/// before every tick. Deterministic: the same inputs give bit-identical trajectories.
/// Non-real-time (it drives the real-time parts in virtual time).
SimulationResult simulate(const canon::Program& program, const plan::MachineLimits& limits,
                          const SimulationOptions& options = {});

}  // namespace opencnc::analysis
