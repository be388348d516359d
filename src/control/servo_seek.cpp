// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, manual mode: seeking a limit switch — a jog that stops at the switch (which is then no
// fault), latches it slowly and backs off onto its free side, reported as an event and in status.
#include <cmath>
#include <limits>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

// Manual mode and idle only: a seek goes past the soft limit, so nothing else may be moving.
// A homed joint searches no further than its soft limit plus the overtravel and comes to rest
// within its soft limits; an unhomed one has neither yet (as its jogs).
Refusal Servo::seek_limit(const Command& c) noexcept {
  if (const Refusal r = need_on(); r != Refusal::None) return r;
  if (mode_ != Mode::Manual) return Refusal::WrongMode;
  if (activity_ != Activity::None) return Refusal::Busy;
  const int j = joint_of(c.axis);
  if (j < 0 || (c.value != 1 && c.value != -1)) return Refusal::BadValue;
  if (manual(j)) return Refusal::HandAxis;
  if (motion_blocked_) return Refusal::Interlock;
  const auto uj = static_cast<std::size_t>(j);
  const JointConfig& jc = config_.joints[uj];
  const int direction = c.value > 0 ? 1 : -1;
  const unsigned bit = direction > 0 ? machine::kSwitchLimitPos : machine::kSwitchLimitNeg;
  if (!(caps_.joints[uj].switches & bit) || !(jc.seek.velocity > 0)) return Refusal::NoLimitSwitch;
  if (toward_active_limit(j, direction)) return Refusal::LimitSwitch;
  const bool limited = homed_[uj] && !jc.wrapped;
  const double soft = (direction > 0 ? jc.max_limit : jc.min_limit) - offset_[uj];
  const double far = direction * std::numeric_limits<double>::infinity();
  seeks_[uj].start(jc.seek, direction, position_[uj], limited ? soft + direction * jc.seek.overtravel : far,
                   limited ? soft : far, movers_[uj]);
  seek_status_[uj] = LimitSeekStatus{};
  seek_status_[uj].direction = static_cast<std::int8_t>(direction);
  seeking_ = static_cast<std::uint16_t>(seeking_ | (1u << j));
  activity_ = Activity::Jog;
  set_state(State::Running);
  return Refusal::None;
}

// Before the movers tick (run_movers): each seek reads its switch and gives its mover the
// phase's move.
void Servo::run_seeks() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    if (!(seeking_ & (1u << j))) continue;
    const auto uj = static_cast<std::size_t>(j);
    const machine::JointInputs& ji = in_.joints[uj];
    LimitSeek& s = seeks_[uj];
    s.tick(config_.joints[uj].seek, position_[uj], s.direction() > 0 ? ji.limit_pos : ji.limit_neg,
           movers_[uj]);
    if (s.phase() == SeekPhase::Done || s.phase() == SeekPhase::Failed) end_seek(j);
  }
}

void Servo::end_seek(int j) noexcept {
  const auto uj = static_cast<std::size_t>(j);
  const JointConfig& jc = config_.joints[uj];
  const LimitSeek& s = seeks_[uj];
  seeking_ = static_cast<std::uint16_t>(seeking_ & ~(1u << j));
  LimitSeekStatus& st = seek_status_[uj];
  st.found = s.phase() == SeekPhase::Done;
  st.tripped_at = s.tripped_at() + offset_[uj];
  st.released_at = s.released_at() + offset_[uj];
  st.rest_at = movers_[uj].position() + offset_[uj];
  ServoEvent e;
  e.kind = EventKind::LimitSeek;
  e.axis = jc.axis;
  e.action = st.found ? 1 : 0;
  e.value = st.found ? st.tripped_at : position_[uj] + offset_[uj];
  emit(e);
  if (!st.found) {  // the switch did not trip where it must: the axis stands past its soft limit
    const double limit = s.direction() > 0 ? jc.max_limit : jc.min_limit;
    enter_fault({FaultKind::SeekNoSwitch, jc.axis, position_[uj] + offset_[uj], limit, tick_});
    homed_[uj] = jc.home.method == HomeMethod::Immediate;
  }
}

bool Servo::sought_switch_only(int j) const noexcept {
  const machine::JointInputs& ji = in_.joints[static_cast<std::size_t>(j)];
  const bool positive = seeks_[static_cast<std::size_t>(j)].direction() > 0;
  return (positive ? ji.limit_pos : ji.limit_neg) && !(positive ? ji.limit_neg : ji.limit_pos);
}

// Jog stop, abort, e-stop, machine off, a power stop: every seek stops where it is.
void Servo::cancel_seeks() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    if (!(seeking_ & (1u << j))) continue;
    seeks_[static_cast<std::size_t>(j)].cancel(movers_[static_cast<std::size_t>(j)]);
  }
  seeking_ = 0;
}

}  // namespace opencnc::control
