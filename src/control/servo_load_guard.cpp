// SPDX-License-Identifier: GPL-3.0-or-later
// The load guard stage: a process load above its levels holds the feed, or stops the run on the
// path and lifts the cutter radially (docs/broaching.md, "Load protection").
#include <algorithm>
#include <cmath>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

const char* to_string(LoadAction a) noexcept {
  switch (a) {
    case LoadAction::None:
      return "none";
    case LoadAction::Hold:
      return "hold";
    case LoadAction::Retract:
      return "retract";
    case LoadAction::Lifted:
      return "lifted";
  }
  return "?";
}

// Every period after the interlocks: count the periods the load has stayed above each level; a
// level acts once (the hold until the operator resumes, the retract until its lift is done).
// The run's stop is the interpolator's, so the coupling stage keeps the slave on its law until
// the path rests; only then does the radial axis move, which moves neither master nor slave.
void Servo::guard_load() noexcept {
  const LoadGuardConfig& g = config_.load_guard;
  if (!g.enabled) return;
  load_kn_ = in_.analog_in[static_cast<std::size_t>(g.input)];
  hold_periods_ = g.hold_kn > 0 && load_kn_ > g.hold_kn ? hold_periods_ + 1 : 0;
  retract_periods_ = g.retract_kn > 0 && load_kn_ > g.retract_kn ? retract_periods_ + 1 : 0;
  if (load_retract_ != LoadRetract::None) {
    step_load_retract();
    return;
  }
  if (activity_ != Activity::Program || aborting_ || power_stop_ || !drives_enabled_) return;
  if (run_id_ != load_run_id_) {  // a new run: what the guard did in the last one is history
    load_run_id_ = run_id_;
    load_action_ = LoadAction::None;
  }
  if (retract_periods_ >= g.confirm_periods) {
    abort();  // along the path at the planned deceleration, couplings held
    load_retract_ = LoadRetract::Stopping;
    emit_load(LoadAction::Retract);
  } else if (hold_periods_ >= g.confirm_periods && !hold_ && state_ == State::Running) {
    hold_ = true;
    set_state(State::Held);
    emit_load(LoadAction::Hold);
  }
}

// Stopping: wait for the run to end at rest; Lifting: the radial axis's mover until it settles.
// A fault, an e-stop or a power failure meanwhile ends the retract where it is.
void Servo::step_load_retract() noexcept {
  if (!drives_enabled_ || power_stop_ || state_ == State::Faulted || state_ == State::EStopped) {
    load_retract_ = LoadRetract::None;
    return;
  }
  if (load_retract_ == LoadRetract::Stopping) {
    if (activity_ != Activity::None) return;
    start_load_lift();
  } else if (activity_ == Activity::None) {
    load_retract_ = LoadRetract::None;
    emit_load(LoadAction::Lifted);
  }
}

void Servo::start_load_lift() noexcept {
  const LoadGuardConfig& g = config_.load_guard;
  const int j = joint_of(g.radial_axis);
  if (j < 0 || manual(j)) {
    load_retract_ = LoadRetract::None;
    return;
  }
  const auto uj = static_cast<std::size_t>(j);
  const JointConfig& jc = config_.joints[uj];
  AxisMover& m = movers_[uj];
  double target = m.position() + g.retract_lift;
  if (homed_[uj] && !jc.wrapped)
    target = std::clamp(target, jc.min_limit - offset_[uj], jc.max_limit - offset_[uj]);
  const double speed = g.retract_speed > 0 ? std::min(g.retract_speed, jc.max_velocity) : jc.max_velocity;
  m.move_to(target, speed);
  activity_ = Activity::Jog;
  set_state(State::Running);
  load_retract_ = LoadRetract::Lifting;
}

void Servo::emit_load(LoadAction a) noexcept {
  load_action_ = a;
  ServoEvent e;
  e.kind = EventKind::LoadGuard;
  e.action = static_cast<std::uint32_t>(a);
  e.value = load_kn_;
  e.run_id = run_id_;
  e.axis = config_.load_guard.radial_axis;
  emit(e);
}

}  // namespace opencnc::control
