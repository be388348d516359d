// SPDX-License-Identifier: GPL-3.0-or-later
// Planner + interpolator in virtual time, with the trace checker on the commanded samples.
#include "opencnc/analysis/simulate.hpp"

#include <cmath>
#include <memory>
#include <optional>

namespace opencnc::analysis {

SimulationResult simulate(const canon::Program& program, const plan::MachineLimits& limits,
                          const SimulationOptions& options) {
  SimulationResult result;
  plan::Planner planner(limits, options.planner);
  if (!planner.start(program)) {
    result.diagnostics = planner.diagnostics();
    return result;
  }
  const traj::InterpolatorConfig ic = planner.interpolator_config();
  auto queue = std::make_unique<traj::BlockQueue>();
  traj::Interpolator interp(*queue, ic, program.start());
  std::optional<TraceChecker> checker;
  if (options.check) checker.emplace(program, limits, ic.period_s);

  const auto max_ticks = static_cast<std::uint64_t>(std::ceil(options.max_time_s / ic.period_s));
  plan::PlanStatus status = plan::PlanStatus::Working;
  traj::TickOutput out;
  out.position = program.start();
  Pose last = program.start();
  std::uint64_t first_move = 0, last_move = 0;
  bool moved = false;
  double rpm = 0, direction = 0, revs = 0;
  for (std::uint64_t n = 0; n < max_ticks; ++n) {
    if (status == plan::PlanStatus::Working) status = planner.pump(*queue);
    traj::TickInput in;
    if (options.ideal_controller) {
      for (int e = 0; e < out.event_count; ++e) {
        const std::uint32_t k = out.events[static_cast<std::size_t>(e)].action;
        if (k >= program.action_count()) continue;
        const canon::Action& a = program.action(k);
        if (a.kind == canon::ActionKind::SpindleSpeed) rpm = a.value;
        if (a.kind == canon::ActionKind::SpindleCw) direction = 1;
        if (a.kind == canon::ActionKind::SpindleCcw) direction = -1;
        if (a.kind == canon::ActionKind::SpindleStop) direction = 0;
      }
      in.spindle_rev_s = direction * rpm / 60.0;
      revs += in.spindle_rev_s * ic.period_s;
      in.spindle_revs = revs;
      in.sync_done = out.state == traj::RunState::WaitingSync;
      in.cycle_start = out.state == traj::RunState::WaitingCycleStart;
    }
    if (options.inputs) options.inputs(n, out, in);
    interp.tick(in, out);
    if (checker) checker->add(out.position, out.segment_first, out.segment_last);
    if (options.observe) options.observe(n, out);
    if (out.position != last) {
      if (!moved) first_move = n;
      moved = true;
      last_move = n;
      last = out.position;
    }
    result.ticks = n + 1;
    if (out.state == traj::RunState::Finished || out.state == traj::RunState::Aborted) break;
  }
  result.state = out.state;
  result.finished = out.state == traj::RunState::Finished;
  result.motion_time_s = moved ? static_cast<double>(last_move - first_move + 1) * ic.period_s : 0.0;
  if (checker) result.report = checker->report();
  result.plan = planner.stats();
  result.diagnostics = planner.diagnostics();
  return result;
}

}  // namespace opencnc::analysis
