// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, manual mode: continuous and incremental jogs (stopping at soft limits), the handwheel and
// homing in sequences, all through the joints' AxisMovers; hand-fed joints follow their scale.
#include <algorithm>
#include <cmath>
#include <limits>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

int Servo::joint_of(int axis) const noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    if (config_.joints[static_cast<std::size_t>(j)].axis == axis) return j;
  }
  return -1;
}

bool Servo::toward_active_limit(int j, double direction) const noexcept {
  const machine::JointInputs& ji = in_.joints[static_cast<std::size_t>(j)];
  return (direction > 0 && ji.limit_pos) || (direction < 0 && ji.limit_neg);
}

bool Servo::any_limit_switch() const noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    if (limit_active_[static_cast<std::size_t>(j)]) return true;
  }
  return false;
}

bool Servo::all_homed() const noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    if (!homed_[static_cast<std::size_t>(j)]) return false;
  }
  return true;
}

void Servo::reset_movers() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    movers_[uj].reset(commanded_[config_.joints[uj].axis] - offset_[uj]);
  }
}

// A continuous jog of a homed joint is a move to its soft limit, so that it stops there exactly
// (the mover never passes a position goal); unhomed joints have no soft limits yet.
Refusal Servo::jog(const Command& c) noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (mode_ != Mode::Manual) return Refusal::WrongMode;
  if ((activity_ != Activity::None && activity_ != Activity::Jog) || seeking_ != 0) return Refusal::Busy;
  const int j = joint_of(c.axis);
  if (j < 0) return Refusal::BadValue;
  if (manual(j)) return Refusal::HandAxis;
  if (motion_blocked_) return Refusal::Interlock;
  const auto uj = static_cast<std::size_t>(j);
  const JointConfig& jc = config_.joints[uj];
  const bool incremental = c.kind == CommandKind::JogIncrement;
  const double speed = incremental ? c.value2 : std::fabs(c.value);
  const double direction = c.value > 0 ? 1.0 : -1.0;
  if (!(speed > 0) || !std::isfinite(c.value) || c.value == 0) return Refusal::BadValue;
  if (toward_active_limit(j, direction)) return Refusal::LimitSwitch;
  AxisMover& m = movers_[uj];
  if (incremental && !m.settled()) return Refusal::Busy;
  const double v = std::min(speed, jc.max_velocity);
  const bool limited = homed_[uj] && !jc.wrapped;
  const double lo = jc.min_limit - offset_[uj], hi = jc.max_limit - offset_[uj];
  if (incremental) {
    const double target = m.position() + c.value;
    m.move_to(limited ? std::clamp(target, lo, hi) : target, v);
  } else if (limited) {
    m.move_to(direction > 0 ? hi : lo, v);
  } else {
    m.run_at(direction * v);
  }
  activity_ = Activity::Jog;
  set_state(State::Running);
  return Refusal::None;
}

Refusal Servo::jog_stop(int axis) noexcept {
  if (activity_ != Activity::Jog) return Refusal::NotApplicable;
  const int j = joint_of(axis);
  if (axis >= 0 && j < 0) return Refusal::BadValue;
  for (int k = 0; k < config_.joint_count; ++k) {
    if (axis >= 0 && k != j) continue;
    const auto uk = static_cast<std::size_t>(k);
    if (seeking(k)) {
      seeks_[uk].cancel(movers_[uk]);
      seeking_ = static_cast<std::uint16_t>(seeking_ & ~(1u << k));
    }
    movers_[uk].stop();
  }
  return Refusal::None;
}

// Every joint's commanded position comes from its mover (the joints not jogging rest where
// they are); once all have settled the jog is over.
void Servo::run_movers() noexcept {
  run_seeks();
  if (activity_ != Activity::Jog) return;  // a seek that found no switch faulted the machine
  bool settled = seeking_ == 0;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (manual(j)) continue;
    commanded_[config_.joints[uj].axis] = movers_[uj].tick() + offset_[uj];
    settled = settled && movers_[uj].settled();
  }
  if (settled) {
    activity_ = Activity::None;
    set_state(State::Idle);
  }
}

// Handwheel counts move the selected axis by the selected step each, exactly (the mover heads for
// the new position at the axis' speed), within the soft limits once homed; never toward an active
// limit switch. Only in Manual mode with nothing else moving; counts turned meanwhile are dropped.
void Servo::run_handwheel() noexcept {
  const std::int32_t counts = in_.handwheel_count - handwheel_last_;
  handwheel_last_ = in_.handwheel_count;
  if (counts == 0 || handwheel_axis_ < 0 || !drives_enabled_ || mode_ != Mode::Manual || motion_blocked_)
    return;
  if ((activity_ != Activity::None && activity_ != Activity::Jog) || seeking_ != 0) return;
  const int j = joint_of(handwheel_axis_);
  if (j < 0) return;
  const auto uj = static_cast<std::size_t>(j);
  const JointConfig& jc = config_.joints[uj];
  const double distance = counts * handwheel_step_;
  if (toward_active_limit(j, distance)) return;
  AxisMover& m = movers_[uj];
  double target = m.goal() + distance;
  if (homed_[uj] && !jc.wrapped)
    target = std::clamp(target, jc.min_limit - offset_[uj], jc.max_limit - offset_[uj]);
  m.move_to(target, jc.max_velocity);
  if (activity_ == Activity::None) {
    activity_ = Activity::Jog;
    set_state(State::Running);
  }
}

// A hand-fed joint is never commanded: its command is wherever the operator has put it.
void Servo::follow_hand_axes() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (manual(j)) commanded_[config_.joints[uj].axis] = position_[uj] + offset_[uj];
  }
}

Refusal Servo::home(int axis) noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (mode_ != Mode::Manual) return Refusal::WrongMode;
  if (activity_ != Activity::None) return Refusal::Busy;
  if (motion_blocked_) return Refusal::Interlock;
  const int j = joint_of(axis);
  if (axis >= 0 && j < 0) return Refusal::BadValue;
  if (j >= 0 && manual(j)) return Refusal::HandAxis;
  std::uint16_t joints = 0;
  for (int k = 0; k < config_.joint_count; ++k) {
    if ((axis < 0 && !manual(k)) || k == j) joints = static_cast<std::uint16_t>(joints | (1u << k));
  }
  start_homing(joints);
  return Refusal::None;
}

// Homes `joints` (a bit each) in their sequences; they are not homed until they are again.
void Servo::start_homing(std::uint16_t joints) noexcept {
  homing_pending_ = joints;
  for (int k = 0; k < config_.joint_count; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    if (!(joints & (1u << k))) continue;
    offset_before_homing_[uk] = offset_[uk];
    homed_[uk] = false;
  }
  homing_active_ = 0;
  activity_ = Activity::Homing;
  set_state(State::Running);
  start_next_homing_group();
}

// What a finished homing found: its edges, and how far the origin moved since the last one.
void Servo::finish_homing(int j) noexcept {
  const auto uj = static_cast<std::size_t>(j);
  HomingStatus& h = homing_status_[uj];
  const JointConfig& jc = config_.joints[uj];
  h.measured = jc.home.method == HomeMethod::DecelMidpoint;
  h.rising_edge = homing_[uj].rising_edge();
  h.falling_edge = homing_[uj].falling_edge();
  h.width = h.falling_edge - h.rising_edge;
  h.origin_shift = homed_once_[uj] ? offset_before_homing_[uj] - offset_[uj] : 0.0;
  homed_once_[uj] = true;
  homing_active_ = static_cast<std::uint16_t>(homing_active_ & ~(1u << j));
  homed_[uj] = true;
  ServoEvent e;
  e.kind = EventKind::Homed;
  e.axis = jc.axis;
  e.value = homing_[uj].latched_at() + offset_[uj];
  emit(e);
}

// The pending joints with the lowest sequence number start together.
void Servo::start_next_homing_group() noexcept {
  int lowest = std::numeric_limits<int>::max();
  for (int j = 0; j < config_.joint_count; ++j) {
    if (homing_pending_ & (1u << j))
      lowest = std::min(lowest, config_.joints[static_cast<std::size_t>(j)].home.sequence);
  }
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (!(homing_pending_ & (1u << j)) || config_.joints[uj].home.sequence != lowest) continue;
    homing_pending_ = static_cast<std::uint16_t>(homing_pending_ & ~(1u << j));
    homing_active_ = static_cast<std::uint16_t>(homing_active_ | (1u << j));
    const machine::JointInputs& ji = in_.joints[uj];
    homing_[uj].start(config_.joints[uj].home,
                      {position_[uj], ji.home, ji.decel, ji.index_count, ji.index_position, ji.home_level});
  }
}

void Servo::run_homing() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (!(homing_active_ & (1u << j))) continue;
    const machine::JointInputs& ji = in_.joints[uj];
    const HomingInputs hi{position_[uj], ji.home, ji.decel, ji.index_count, ji.index_position, ji.home_level};
    homing_[uj].tick(config_.joints[uj].home, hi, movers_[uj], offset_[uj]);
    if (homing_[uj].failed()) {
      enter_fault({FaultKind::Homing, config_.joints[uj].axis, position_[uj] + offset_[uj], 0, tick_});
      return;
    }
    if (homing_[uj].done()) finish_homing(j);
  }
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (manual(j)) continue;
    commanded_[config_.joints[uj].axis] = movers_[uj].tick() + offset_[uj];
  }
  if (homing_active_ == 0) {
    if (homing_pending_ != 0) {
      start_next_homing_group();
    } else {
      activity_ = Activity::None;
      set_state(State::Idle);
    }
  }
}

}  // namespace opencnc::control
