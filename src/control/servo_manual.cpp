// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, manual mode: continuous and incremental jogs (stopping at soft limits) and homing in
// sequences, both through the joints' AxisMovers.
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
  if (activity_ != Activity::None && activity_ != Activity::Jog) return Refusal::Busy;
  const int j = joint_of(c.axis);
  if (j < 0) return Refusal::BadValue;
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
    if (axis < 0 || k == j) movers_[static_cast<std::size_t>(k)].stop();
  }
  return Refusal::None;
}

// Every joint's commanded position comes from its mover (the joints not jogging rest where
// they are); once all have settled the jog is over.
void Servo::run_movers() noexcept {
  bool settled = true;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    commanded_[config_.joints[uj].axis] = movers_[uj].tick() + offset_[uj];
    settled = settled && movers_[uj].settled();
  }
  if (settled) {
    activity_ = Activity::None;
    set_state(State::Idle);
  }
}

Refusal Servo::home(int axis) noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (mode_ != Mode::Manual) return Refusal::WrongMode;
  if (activity_ != Activity::None) return Refusal::Busy;
  const int j = joint_of(axis);
  if (axis >= 0 && j < 0) return Refusal::BadValue;
  homing_pending_ = 0;
  for (int k = 0; k < config_.joint_count; ++k) {
    if (axis < 0 || k == j) {
      homing_pending_ = static_cast<std::uint16_t>(homing_pending_ | (1u << k));
      homed_[static_cast<std::size_t>(k)] = false;
    }
  }
  homing_active_ = 0;
  activity_ = Activity::Homing;
  set_state(State::Running);
  start_next_homing_group();
  return Refusal::None;
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
                      {feedback_[uj], ji.home, ji.decel, ji.index_count, ji.index_position});
  }
}

void Servo::run_homing() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (!(homing_active_ & (1u << j))) continue;
    const machine::JointInputs& ji = in_.joints[uj];
    const HomingInputs hi{feedback_[uj], ji.home, ji.decel, ji.index_count, ji.index_position};
    homing_[uj].tick(config_.joints[uj].home, hi, movers_[uj], offset_[uj]);
    if (homing_[uj].done()) {
      homing_active_ = static_cast<std::uint16_t>(homing_active_ & ~(1u << j));
      homed_[uj] = true;
      ServoEvent e;
      e.kind = EventKind::Homed;
      e.axis = config_.joints[uj].axis;
      e.value = homing_[uj].latched_at() + offset_[uj];
      emit(e);
    }
  }
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
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
