// SPDX-License-Identifier: GPL-3.0-or-later
// Servo: joint limits, pitch-error tables and EDM machining conditions changed by an admin while
// nothing moves — staged, applied together by one command, so that the tick takes all or none.
#include <cmath>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

namespace {

bool valid(const JointLimits& l, bool wrapped) noexcept {
  const bool finite = std::isfinite(l.max_velocity) && std::isfinite(l.max_acceleration) &&
                      std::isfinite(l.min_limit) && std::isfinite(l.max_limit) &&
                      std::isfinite(l.max_following_error) && std::isfinite(l.home_final_velocity) &&
                      std::isfinite(l.backlash) && std::isfinite(l.takeup_velocity) &&
                      std::isfinite(l.takeup_acceleration);
  return finite && l.max_velocity > 0 && l.max_acceleration > 0 && l.max_following_error > 0 &&
         l.home_final_velocity > 0 && (wrapped || l.min_limit < l.max_limit) && l.backlash >= 0 &&
         l.takeup_velocity >= 0 && l.takeup_acceleration >= 0;
}

/// A table the lookup can use: at most kMaxPitchPoints, finite, positions strictly increasing.
bool valid(const motion::PitchTable& t) noexcept {
  if (t.count < 0 || t.count > motion::kMaxPitchPoints) return false;
  for (int i = 0; i < t.count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!std::isfinite(t.position[k]) || !std::isfinite(t.forward[k]) || !std::isfinite(t.reverse[k]))
      return false;
    if (i > 0 && !(t.position[k] > t.position[k - 1])) return false;
  }
  return true;
}

/// A condition the gap servo can run: a number, finite values in the ranges the profile's loader
/// allows (the loader checks the rest, against the axes' limits).
bool valid(const machine::EdmCondition& c) noexcept {
  const double values[] = {c.on_time_us,        c.off_time_us,     c.peak_current_a,   c.voltage_v,
                           c.servo_reference_v, c.gain_mm_s_per_v, c.max_forward_mm_s, c.max_retract_mm_s,
                           c.filter_s,          c.short_timeout_s, c.jump_height_mm,   c.jump_period_s,
                           c.jump_speed_mm_s,   c.orbit_radius_mm, c.orbit_step_mm,    c.orbit_period_s,
                           c.finish_timeout_s};
  for (const double v : values)
    if (!std::isfinite(v) || v < 0) return false;
  return c.number >= 1 && c.number <= 99 && c.on_time_us > 0 && c.peak_current_a > 0 && c.voltage_v > 0 &&
         c.servo_reference_v > 0 && c.servo_reference_v < c.voltage_v && c.gain_mm_s_per_v > 0 &&
         c.max_forward_mm_s > 0 && c.max_retract_mm_s > 0 && c.short_timeout_s > 0 &&
         (c.polarity == 1 || c.polarity == -1) && c.jump_mode <= machine::JumpMode::Path &&
         c.orbit <= machine::OrbitKind::Star &&
         (c.jump_period_s == 0 || (c.jump_height_mm > 0 && c.jump_speed_mm_s > 0)) &&
         (c.orbit == machine::OrbitKind::None || (c.orbit_radius_mm > 0 && c.orbit_period_s > 0));
}

/// A table the gap servo can select from: each condition valid and numbered once.
bool valid(const EdmConditionTable& t) noexcept {
  if (t.count < 0 || t.count > machine::kMaxEdmConditions) return false;
  for (int i = 0; i < t.count; ++i) {
    const machine::EdmCondition& c = t.conditions[static_cast<std::size_t>(i)];
    if (!valid(c)) return false;
    for (int k = 0; k < i; ++k)
      if (t.conditions[static_cast<std::size_t>(k)].number == c.number) return false;
  }
  return true;
}

}  // namespace

// Only marked here: the conditions are read, checked and copied in the apply, after which the
// controller may write the buffer again (one buffer, no reader between the two).
Refusal Servo::stage_edm_conditions() noexcept {
  if (!config_.edm.enabled) {
    staged_invalid_ = true;
    return Refusal::NotApplicable;
  }
  staged_conditions_ = true;
  return Refusal::None;
}

// The table is checked here, once, so that the lookup in every period can trust it (a bounded
// loop over at most 256 points; the controller does not write this buffer until the apply). A
// stage naming the buffer the tick reads is refused: the controller broke the hand-over.
Refusal Servo::stage_pitch_table(const Command& c) noexcept {
  const int j = c.axis;
  const auto uj = static_cast<std::size_t>(j);
  if (j < 0 || j >= config_.joint_count || j >= motion::kMaxCompensatedJoints || c.table_buffer > 1 ||
      !config_.compensation.joints[uj].enabled ||
      channels_->pitch_tables.reading[uj].index.load(std::memory_order_relaxed) == c.table_buffer ||
      !valid(channels_->pitch_tables.joints[uj][c.table_buffer])) {
    staged_invalid_ = true;
    return Refusal::BadValue;
  }
  staged_buffer_[uj] = c.table_buffer;
  staged_tables_ = static_cast<std::uint16_t>(staged_tables_ | (1u << j));
  return Refusal::None;
}

Refusal Servo::stage_joint_limits(const Command& c) noexcept {
  const int j = c.axis;
  if (j < 0 || j >= config_.joint_count ||
      !valid(c.limits, config_.joints[static_cast<std::size_t>(j)].wrapped)) {
    staged_invalid_ = true;
    return Refusal::BadValue;
  }
  staged_limits_[static_cast<std::size_t>(j)] = c.limits;
  staged_joints_ = static_cast<std::uint16_t>(staged_joints_ | (1u << j));
  return Refusal::None;
}

// Nothing may move: a jog, homing or a program (running, held or stopped) planned with the old
// limits would finish under the new ones. A homed joint must stand within its new soft limits,
// or the soft-limit check would fault it at once.
Refusal Servo::apply_joint_limits() noexcept {
  const std::uint16_t staged = staged_joints_, tables = staged_tables_;
  const bool invalid = staged_invalid_, conditions = staged_conditions_;
  staged_joints_ = staged_tables_ = 0;
  staged_invalid_ = staged_conditions_ = false;
  if (invalid || (conditions && !valid(channels_->edm_conditions))) return Refusal::BadValue;
  if (staged == 0 && tables == 0 && !conditions) return Refusal::NotApplicable;
  if (activity_ != Activity::None || state_ == State::Running || state_ == State::Held ||
      state_ == State::Stopped)
    return Refusal::Busy;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const JointConfig& jc = config_.joints[uj];
    if (!(staged & (1u << j)) || !homed_[uj] || jc.wrapped || manual(j)) continue;
    const double x = commanded_[jc.axis];
    if (x < staged_limits_[uj].min_limit || x > staged_limits_[uj].max_limit) return Refusal::SoftLimit;
  }
  for (int j = 0; j < config_.joint_count; ++j) {
    if (!(staged & (1u << j))) continue;
    const auto uj = static_cast<std::size_t>(j);
    JointConfig& jc = config_.joints[uj];
    const JointLimits& l = staged_limits_[uj];
    jc.max_velocity = l.max_velocity;
    jc.max_acceleration = l.max_acceleration;
    jc.min_limit = l.min_limit;
    jc.max_limit = l.max_limit;
    jc.max_following_error = l.max_following_error;
    jc.home.final_velocity = l.home_final_velocity;
    movers_[uj].configure(config_.period_s, jc.max_acceleration, jc.max_jerk, movers_[uj].position());
    if (uj < config_.compensation.joints.size() && config_.compensation.joints[uj].enabled) {
      motion::JointCompensation& c = config_.compensation.joints[uj];
      c.backlash = l.backlash;
      c.max_velocity = l.takeup_velocity;
      c.max_acceleration = l.takeup_acceleration;
      comp_.set_backlash(j, l.backlash, l.takeup_velocity, l.takeup_acceleration);
    }
  }
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (!(tables & (1u << j))) continue;
    comp_.set_pitch_table(j, &channels_->pitch_tables.joints[uj][staged_buffer_[uj]]);
    // Published after the switch: the buffer read until now is the controller's from here on.
    channels_->pitch_tables.reading[uj].index.store(static_cast<std::int8_t>(staged_buffer_[uj]),
                                                    std::memory_order_release);
  }
  if (conditions) {  // a program selects from them from its next M180 on (nothing runs now)
    config_.edm.conditions = channels_->edm_conditions.conditions;
    config_.edm.condition_count = channels_->edm_conditions.count;
  }
  configure_gap_servo();  // the jump accelerates within the tool axis' limit, from the new conditions
  return Refusal::None;
}

}  // namespace opencnc::control
