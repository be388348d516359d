// SPDX-License-Identifier: GPL-3.0-or-later
// Simulated spindle: rate-limited speed, position by trapezoidal integration, orient by a
// braking-distance law, quantised encoder with an index mark at angle 0, the drive's torque from
// the rotor's acceleration, friction and a load.
#include "opencnc/machine/sim_spindle.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::machine {

SimSpindle::SimSpindle(const SimSpindleConfig& config, double servo_period_s, int substeps,
                       bool linear_periods)
    : config_(config),
      h_(servo_period_s / substeps),
      period_s_(servo_period_s),
      max_step_rps_(config.acceleration_rpm_s / 60.0 * h_),
      linear_periods_(linear_periods) {}

void SimSpindle::begin_period(const SpindleOutputs& cmd, bool powered) noexcept {
  cmd_ = cmd;
  powered_ = powered && !fault_;
  position_at_period_start_ = position_rev_;
  speed_at_period_start_ = speed_rps_;
  const double rps = std::min(cmd.speed_rpm, config_.max_rpm) / 60.0;
  switch (cmd.direction) {
    case SpindleDirection::Clockwise:
      target_rps_ = rps;
      break;
    case SpindleDirection::Counterclockwise:
      target_rps_ = -rps;
      break;
    case SpindleDirection::Stopped:
      target_rps_ = 0;
      break;
  }
  if (!powered_) target_rps_ = 0;
  // At the target speed every sub-step adds speed·h: the period is speed·T.
  period_done_ = linear_periods_ && !orienting() && speed_rps_ == target_rps_;
  if (period_done_) position_rev_ += speed_rps_ * period_s_;
}

// Orient: head for the target angle the short way round, never faster than the speed from
// which the ramp limit can still stop at the target: v = sqrt(2·a·|error|).
double SimSpindle::orient_target_speed() const noexcept {
  const double target = cmd_.orient_angle_deg / 360.0;
  double error = target - (position_rev_ - std::floor(position_rev_));
  error -= std::floor(error + 0.5);  // into [-0.5, 0.5)
  const double a_rps2 = config_.acceleration_rpm_s / 60.0;
  const double v = std::min(config_.orient_rpm / 60.0, std::sqrt(2.0 * a_rps2 * std::abs(error)));
  return std::copysign(v, error);
}

void SimSpindle::substep() noexcept {
  if (period_done_) return;
  const double target = orienting() ? orient_target_speed() : target_rps_;
  // Lands on the target exactly (speed + (target − speed) may miss it by an ulp).
  const double next = std::abs(target - speed_rps_) <= max_step_rps_
                          ? target
                          : speed_rps_ + std::copysign(max_step_rps_, target - speed_rps_);
  position_rev_ += 0.5 * (speed_rps_ + next) * h_;
  speed_rps_ = next;
}

// The index mark is at whole revolutions; a period turns far less than one revolution at
// any real spindle speed (60 000 rpm at 1 ms is a turn per period), so the marks passed are
// the difference of the whole turns at the two ends.
void SimSpindle::end_period() noexcept {
  update_torque();
  const double before = std::floor(position_at_period_start_);
  const double after = std::floor(position_rev_);
  if (before == after) return;
  index_count_ += static_cast<std::uint32_t>(std::abs(after - before));
  index_position_rev_ = after > before ? after : after + 1;
}

// Torque = I·α + friction and load against the turning: α over the period (the ramp's constant
// acceleration within it), the turning direction that of the period's mean speed. A drive without
// power reports nothing; a spindle standing still needs none.
void SimSpindle::update_torque() noexcept {
  constexpr double kTwoPi = 6.283185307179586;
  if (!powered_) {
    torque_nm_ = 0;
    return;
  }
  const double alpha = kTwoPi * (speed_rps_ - speed_at_period_start_) / period_s_;
  const double mean = speed_at_period_start_ + speed_rps_;
  const double drag =
      mean == 0 ? 0.0
                : config_.friction_nm + config_.viscous_nm_per_krpm * std::abs(speed_rps_) * 0.06 + load_nm_;
  torque_nm_ = config_.inertia_kgm2 * alpha + std::copysign(drag, mean);
}

void SimSpindle::sample(SpindleInputs& in) const noexcept {
  const double cpr = config_.encoder_counts_per_rev;
  in.position_rev = cpr > 0 ? std::floor(position_rev_ * cpr) / cpr : 0.0;
  in.speed_rpm = speed_rps_ * 60.0;
  in.index_count = cpr > 0 ? index_count_ : 0;
  in.index_position_rev = cpr > 0 ? index_position_rev_ : 0.0;
  const double cmd_rpm = target_rps_ * 60.0;
  in.at_speed = powered_ && !orienting() &&
                std::abs(in.speed_rpm - cmd_rpm) <= config_.at_speed_tolerance * std::abs(cmd_rpm);
  double error_deg = cmd_.orient_angle_deg - 360.0 * (position_rev_ - std::floor(position_rev_));
  error_deg -= 360.0 * std::floor(error_deg / 360.0 + 0.5);
  in.orient_done = orienting() && std::abs(error_deg) <= config_.orient_tolerance_deg &&
                   std::abs(speed_rps_) * 360.0 * period_s_ <= config_.orient_tolerance_deg;
  in.fault = fault_;
  in.torque_nm = torque_nm_;
}

}  // namespace opencnc::machine
