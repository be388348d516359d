// SPDX-License-Identifier: GPL-3.0-or-later
// Servo: the state transitions — one function per command, and the stops (e-stop, fault, halt).
// docs/controller.md has the same table in words; tests/control/servo_state_test.cpp every row.
#include <algorithm>
#include <cmath>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

namespace {

bool on_state(State s) noexcept {
  return s == State::Idle || s == State::Running || s == State::Held || s == State::Stopped;
}

/// A stop: what was sent before it and would start something is dropped once it has acted.
bool is_stop(CommandKind k) noexcept {
  return k == CommandKind::EStop || k == CommandKind::MachineOff || k == CommandKind::Abort ||
         k == CommandKind::FeedHold;
}

/// Commands that start motion, power or the process (or undo a stop): never applied after a stop
/// that was sent later than they were.
bool starts_something(const Command& c) noexcept {
  switch (c.kind) {
    case CommandKind::Reset:
    case CommandKind::MachineOn:
    case CommandKind::JogContinuous:
    case CommandKind::JogIncrement:
    case CommandKind::Home:
    case CommandKind::StartRun:
    case CommandKind::CycleStart:
    case CommandKind::Resume:
    case CommandKind::ToolChanged:
    case CommandKind::SpindleOn:
    case CommandKind::SeekLimit:
    case CommandKind::StartCut:
      return true;
    case CommandKind::Coolant:
      return c.flag;
    case CommandKind::SetHandwheel:
      return c.axis >= 0;
    default:
      return false;
  }
}

}  // namespace

// The order of sending decides, not the order of arrival: a stop that overtook older commands on
// the urgent lane (ServoChannels::urgent) drops those that would start something.
Refusal Servo::apply(const Command& c) noexcept {
  if (c.seq != 0) {
    if (starts_something(c) && c.seq < stop_seq_) return Refusal::Superseded;
    if (is_stop(c.kind) && c.seq > stop_seq_) stop_seq_ = c.seq;
  }
  switch (c.kind) {
    case CommandKind::EStop:
      if (state_ != State::EStopped) enter_estop();
      return Refusal::None;
    case CommandKind::Reset:
      return reset();
    case CommandKind::MachineOn:
      return machine_on();
    case CommandKind::MachineOff:
      return machine_off();
    case CommandKind::SetMode:
      return set_mode(c.mode);
    case CommandKind::JogContinuous:
    case CommandKind::JogIncrement:
      return jog(c);
    case CommandKind::JogStop:
      return jog_stop(c.axis);
    case CommandKind::Home:
      return home(c.axis);
    case CommandKind::StartRun:
      return start_run(c);
    case CommandKind::CycleStart:
      return cycle_start();
    case CommandKind::FeedHold:
      return feed_hold();
    case CommandKind::Resume:
      return resume();
    case CommandKind::Abort:
      return abort();
    case CommandKind::SetSingleBlock:
      single_block_ = c.flag;
      return Refusal::None;
    case CommandKind::SetOptionalStop:
      optional_stop_ = c.flag;
      return Refusal::None;
    case CommandKind::SetFeedOverride:
      return set_override(feed_override_, c.value, config_.interpolator.max_feed_override);
    case CommandKind::SetRapidOverride:
      return set_override(rapid_override_, c.value, 1.0);
    case CommandKind::SetSpindleOverride:
      return set_override(spindle_override_, c.value, config_.max_spindle_override);
    case CommandKind::ToolChanged:
      return tool_changed();
    case CommandKind::SpindleOn:
    case CommandKind::SpindleOff:
    case CommandKind::Coolant:
      return manual_spindle_or_coolant(c);
    case CommandKind::SetHandwheel:
      return set_handwheel(c);
    case CommandKind::StageJointLimits:
      return stage_joint_limits(c);
    case CommandKind::ApplyJointLimits:
      return apply_joint_limits();
    case CommandKind::StagePitchTable:
      return stage_pitch_table(c);
    case CommandKind::StageEdmConditions:
      return stage_edm_conditions();
    case CommandKind::SeekLimit:
      return seek_limit(c);
    case CommandKind::StartCut:
      return torch_.enabled() && torch_.start_cut() ? Refusal::None : Refusal::NotApplicable;
  }
  return Refusal::BadValue;
}

Refusal Servo::need_on() const noexcept {
  switch (state_) {
    case State::EStopped:
      return Refusal::EStopActive;
    case State::Faulted:
      return Refusal::Faulted;
    case State::Off:
      return Refusal::MachineOff;
    default:
      return power_stop_ ? Refusal::Busy : Refusal::None;
  }
}

Refusal Servo::reset() noexcept {
  if (state_ == State::EStopped) {
    if (!in_.estop_ok) return Refusal::EStopInput;
    if (estop_rule_) return Refusal::Interlock;
    set_state(State::Off);
    return Refusal::None;
  }
  if (state_ != State::Faulted) return Refusal::NotApplicable;
  const int j = joint_of(fault_.axis);
  const bool amp =
      fault_.kind == FaultKind::AmpFault && j >= 0 && in_.joints[static_cast<std::size_t>(j)].amp_fault;
  const bool power = fault_.kind == FaultKind::PowerLoss && caps_.power_monitor &&
                     (!in_.power.mains_ok || (caps_.ups && in_.power.ups_on_battery));
  const bool alarm = fault_.kind == FaultKind::ProcessAlarm && fault_.axis >= 0 &&
                     ((alarms_active_ >> fault_.axis) & 1u) != 0;
  if (amp || power || alarm) return Refusal::FaultPersists;
  fault_ = Fault{};
  power_stop_ = false;
  stop_scale_ = stop_scale_max_ = 1;
  set_state(State::Off);
  return Refusal::None;
}

Refusal Servo::machine_on() noexcept {
  if (state_ != State::Off) return on_state(state_) ? Refusal::NotApplicable : need_on();
  follow_feedback();
  reset_movers();
  drives_enabled_ = true;
  set_state(State::Idle);
  return Refusal::None;
}

Refusal Servo::machine_off() noexcept {
  if (!on_state(state_)) return state_ == State::Off ? Refusal::NotApplicable : need_on();
  halt(RunEnd::MachineOff);
  set_state(State::Off);
  return Refusal::None;
}

Refusal Servo::set_mode(Mode m) noexcept {
  if (activity_ != Activity::None) return Refusal::Busy;
  mode_ = m;
  return Refusal::None;
}

Refusal Servo::start_run(const Command& c) noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (mode_ != c.run_mode || mode_ == Mode::Manual) return Refusal::WrongMode;
  if (activity_ != Activity::None) return Refusal::Busy;
  if (config_.homing_required && !all_homed()) return Refusal::NotHomed;
  if (any_limit_switch()) return Refusal::LimitSwitch;
  if (motion_blocked_ || alarm_blocks_motion_) return Refusal::Interlock;
  // Blocks and actions below the fences belong to runs that have ended.
  channels_->blocks.pop(static_cast<std::size_t>(std::min<std::uint64_t>(
      c.first_block - std::min(c.first_block, channels_->blocks.popped()), channels_->blocks.available())));
  channels_->actions.drop_until(c.first_action);
  if (channels_->blocks.popped() == c.first_block && channels_->blocks.available() > 0) {
    const traj::MotionBlock& first = channels_->blocks.peek(0);
    for (int j = 0; j < config_.joint_count; ++j) {
      const int axis = config_.joints[static_cast<std::size_t>(j)].axis;
      if (!manual(j) && std::fabs(first.base[axis] - commanded_[axis]) > 1e-6) return Refusal::StartMismatch;
    }
  }
  interp_.restart(commanded_);
  gap_.begin_run(commanded_);
  torch_.begin_run();
  if (!c.flag) torch_.forget_interrupted_cut();
  tick_out_ = traj::TickOutput{};
  tick_out_.position = commanded_;
  run_id_ = c.run_id;
  run_mode_ = c.run_mode;
  hold_ = cycle_start_edge_ = abort_edge_ = sync_done_edge_ = aborting_ = false;
  sync_step_ = SyncStep::None;
  sync_seq_ = traj::kNoBlock;
  hand_wait_ = HandWait{};
  hand_guard_ = false;
  activity_ = Activity::Program;
  set_state(State::Running);
  return Refusal::None;
}

Refusal Servo::cycle_start() noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (activity_ != Activity::Program || aborting_) return Refusal::NotApplicable;
  if (state_ != State::Held && state_ != State::Stopped) return Refusal::NotApplicable;
  if (motion_blocked_ || alarm_blocks_motion_) return Refusal::Interlock;
  if (hand_guard_ && !hand_axis_there(true)) return Refusal::HandAxis;
  hold_ = false;
  cycle_start_edge_ = true;
  set_state(State::Running);
  return Refusal::None;
}

Refusal Servo::feed_hold() noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (activity_ != Activity::Program || aborting_ || state_ != State::Running) return Refusal::NotApplicable;
  hold_ = true;
  set_state(State::Held);
  return Refusal::None;
}

Refusal Servo::resume() noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (activity_ != Activity::Program || aborting_) return Refusal::NotApplicable;
  if (state_ == State::Stopped) return cycle_start();
  if (state_ != State::Held) return Refusal::NotApplicable;
  if (motion_blocked_ || alarm_blocks_motion_) return Refusal::Interlock;
  if (hand_guard_ && !hand_axis_there(true)) return Refusal::HandAxis;
  hold_ = false;
  set_state(State::Running);
  return Refusal::None;
}

// A controlled stop of whatever moves; Idle once it has stopped. Always accepted.
Refusal Servo::abort() noexcept {
  switch (activity_) {
    case Activity::Program:
      hold_ = false;
      abort_edge_ = aborting_ = true;
      sync_step_ = SyncStep::None;
      break;
    case Activity::Homing:
      for (int j = 0; j < config_.joint_count; ++j)
        homing_[static_cast<std::size_t>(j)].cancel(movers_[static_cast<std::size_t>(j)]);
      homing_pending_ = homing_active_ = 0;
      activity_ = Activity::Jog;  // the movers bring the joints to rest, then Idle
      break;
    case Activity::Jog:
      cancel_seeks();
      for (int j = 0; j < config_.joint_count; ++j) movers_[static_cast<std::size_t>(j)].stop();
      break;
    case Activity::None:
      break;
  }
  return Refusal::None;
}

Refusal Servo::set_override(double& target, double value, double max) noexcept {
  if (!(value >= 0 && value <= max)) return Refusal::BadValue;
  target = value;
  return Refusal::None;
}

// The handwheel moves `axis` by `value` per count (one of the profile's steps, if it lists any);
// axis −1 takes it off every axis.
Refusal Servo::set_handwheel(const Command& c) noexcept {
  if (!caps_.handwheel) return Refusal::NotApplicable;
  if (c.axis < 0) {
    handwheel_axis_ = -1;
    return Refusal::None;
  }
  const int j = joint_of(c.axis);
  if (j < 0) return Refusal::BadValue;
  if (manual(j)) return Refusal::HandAxis;
  bool listed = config_.handwheel_step_count == 0 && c.value > 0 && std::isfinite(c.value);
  for (int k = 0; k < config_.handwheel_step_count; ++k)
    listed = listed || c.value == config_.handwheel_steps[static_cast<std::size_t>(k)];
  if (!listed) return Refusal::BadValue;
  handwheel_axis_ = c.axis;
  handwheel_step_ = c.value;
  handwheel_last_ = in_.handwheel_count;  // counts turned before this do not move it
  return Refusal::None;
}

Refusal Servo::tool_changed() noexcept {
  if (sync_step_ != SyncStep::ManualTool) return Refusal::NotApplicable;
  manual_tool_done_ = true;
  return Refusal::None;
}

Refusal Servo::manual_spindle_or_coolant(const Command& c) noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (mode_ != Mode::Manual) return Refusal::WrongMode;
  switch (c.kind) {
    case CommandKind::SpindleOn:
      if (!(c.value > 0 && c.value <= std::max(config_.spindle_max_rpm, 0.0))) return Refusal::BadValue;
      if (spindle_direction_ == machine::SpindleDirection::Stopped && !spindle_may_start())
        return Refusal::Interlock;
      spindle_rpm_ = c.value;
      css_max_rpm_ = 0;  // the operator's speed is in rpm
      spindle_direction_ =
          c.flag ? machine::SpindleDirection::Clockwise : machine::SpindleDirection::Counterclockwise;
      spindle_changed_tick_ = tick_;
      orient_ = false;
      return Refusal::None;
    case CommandKind::SpindleOff:
      spindle_direction_ = machine::SpindleDirection::Stopped;
      orient_ = false;
      return Refusal::None;
    default:
      if (c.coolant != Coolant::Flood && c.coolant != Coolant::Mist) return Refusal::BadValue;
      (c.coolant == Coolant::Flood ? flood_ : mist_) = c.flag;
      return Refusal::None;
  }
}

// --- stops -----------------------------------------------------------------------------------

// Everything stops at once: the run (if any) ends, homing is cancelled, the commanded position
// is the actual one, the spindle and coolant stop. The caller sets the new state.
void Servo::halt(RunEnd why) noexcept {
  if (activity_ == Activity::Program) end_run(why);
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (homing_[uj].active()) homing_[uj].cancel(movers_[uj]);
  }
  cancel_seeks();
  homing_pending_ = homing_active_ = 0;
  activity_ = Activity::None;
  hold_ = cycle_start_edge_ = abort_edge_ = aborting_ = false;
  wait_ = Wait::None;
  stop_reason_ = StopReason::None;
  hand_wait_ = HandWait{};
  hand_guard_ = false;
  drives_enabled_ = false;
  // Steppers lose their place without drive power: they must home again.
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (stepper_slot_[uj] >= 0 && config_.joints[uj].home.method != HomeMethod::Immediate) homed_[uj] = false;
  }
  follow_feedback();
  reset_movers();
  stop_spindle_and_coolant();
}

void Servo::enter_estop() noexcept {
  halt(RunEnd::EStopped);
  set_state(State::EStopped);
}

void Servo::enter_fault(const Fault& f) noexcept {
  halt(RunEnd::Faulted);
  power_stop_ = false;  // the stop's scale stays in status until reset
  fault_ = f;
  set_state(State::Faulted);
  ServoEvent e;
  e.kind = EventKind::Fault;
  e.fault = f;
  e.state = state_;
  emit(e);
}

void Servo::set_state(State s) noexcept {
  state_ = s;
  if (s != State::Stopped) stop_reason_ = StopReason::None;
}

}  // namespace opencnc::control
