// SPDX-License-Identifier: GPL-3.0-or-later
// The power-fail stop's deceleration: as planned while the DC link's energy lasts the stop, harder
// (up to the axes' peak deceleration) by as little as makes it last.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

// ½·C·(V² − V_min²): what the drives can still take from the link before they trip.
double Servo::dc_link_energy_j() const noexcept {
  const PowerStopConfig& p = config_.power_stop;
  if (p.dc_link_capacitance_f <= 0) return 0;
  const double v = in_.power.dc_link_v;
  return std::max(0.0, 0.5 * p.dc_link_capacitance_f * (v * v - p.dc_link_min_v * p.dc_link_min_v));
}

// The path brakes every axis of it alike: the hardest stop is the one the axis with the least
// margin (peak over planned) allows. An axis without a stated peak has none. The coupled slave
// moves with its master through the law, so it counts whenever a law holds.
double Servo::stop_scale_bound() const noexcept {
  double bound = 1e300;
  bool any = false;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const JointConfig& jc = config_.joints[uj];
    const bool coupled = law_.active() && (j == slave_joint_ || j == master_joint_);
    if (manual(j) || (joint_velocity_[uj] == 0 && !coupled)) continue;
    any = true;
    const double ratio = jc.max_acceleration > 0 ? jc.peak_deceleration / jc.max_acceleration : 1.0;
    bound = std::min(bound, std::max(1.0, ratio));
  }
  return any ? bound : 1.0;
}

// Chosen at the signal and looked at again every period of the stop (only ever raised, so that a
// link that drains faster than foreseen is met by braking harder still). The energy the normal
// stop needs: the link's standing load over the stop's time, and the drives' motion power now
// (force times speed, what it costs to keep moving) falling with the speed to rest, that is half
// of it over the braking; the moving average's window follows the braking at the standing load.
// With the energy E left above the minimum voltage, braking at s times the budget a from path
// speed v takes v/(a·s): s = (P_idle + P_motion/2)·v / (a·(E − P_idle·window)).
void Servo::choose_stop_scale() noexcept {
  const PowerStopConfig& p = config_.power_stop;
  const double v = std::fabs(tick_out_.path_velocity);
  const double a = tick_out_.path_acceleration;
  if (p.dc_link_capacitance_f <= 0 || v == 0 || a <= 0) return;
  double motion_w = 0;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const double per_unit = config_.joints[uj].rotary ? std::numbers::pi / 180.0 : 1e-3;  // to m, rad
    motion_w += in_.joints[uj].effort * in_.joints[uj].velocity * per_unit;
  }
  const double braking_w = p.dc_link_idle_power_w + 0.5 * std::max(0.0, motion_w);
  const double window_s = config_.interpolator.filter_ticks * config_.period_s;
  const double left_j = dc_link_energy_j() - p.dc_link_idle_power_w * window_s;
  const double need = left_j > 0 ? braking_w * v / (a * left_j) : stop_scale_max_;
  stop_scale_ = std::min(stop_scale_max_, std::max(stop_scale_, need));
}

}  // namespace opencnc::control
