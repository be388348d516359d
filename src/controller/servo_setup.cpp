// SPDX-License-Identifier: GPL-3.0-or-later
// Profile → planner limits, planner settings and ServoConfig.
#include "opencnc/controller/servo_setup.hpp"

#include <algorithm>

namespace opencnc::control {

namespace {

HomeMethod home_method(config::HomingMethod m) {
  switch (m) {
    case config::HomingMethod::Immediate:
      return HomeMethod::Immediate;
    case config::HomingMethod::Switch:
      return HomeMethod::Switch;
    case config::HomingMethod::SwitchIndex:
      return HomeMethod::SwitchIndex;
    case config::HomingMethod::Index:
      return HomeMethod::Index;
    case config::HomingMethod::DecelHome:
      return HomeMethod::DecelHome;
  }
  return HomeMethod::Immediate;
}

}  // namespace

plan::MachineLimits machine_limits(const config::MachineProfile& profile) {
  plan::MachineLimits m;
  m.axes = profile.axis_mask();
  for (const config::AxisProfile& a : profile.axes) {
    m.axis[static_cast<std::size_t>(index(a.axis))] = {a.max_velocity, a.max_acceleration, a.max_jerk};
  }
  return m;
}

plan::PlannerConfig planner_config(const config::MachineProfile& profile) {
  plan::PlannerConfig c;
  c.servo_period_s = profile.servo_period_s;
  c.lookahead_moves = static_cast<std::size_t>(std::max(2, profile.planner.lookahead));
  return c;
}

ServoConfig servo_config(const config::MachineProfile& profile) {
  ServoConfig s;
  s.period_s = profile.servo_period_s;
  s.joint_count = static_cast<int>(std::min<std::size_t>(profile.axes.size(), machine::kMaxJoints));
  for (const config::AxisProfile& a : profile.axes) {
    if (a.joint < 0 || a.joint >= machine::kMaxJoints) continue;
    JointConfig& j = s.joints[static_cast<std::size_t>(a.joint)];
    j.axis = static_cast<std::int8_t>(index(a.axis));
    j.rotary = a.rotary;
    j.wrapped = a.wrapped;
    j.drive = a.drive;
    j.counts_per_unit = a.counts_per_unit;
    j.max_velocity = a.max_velocity;
    j.max_acceleration = a.max_acceleration;
    j.max_jerk = a.max_jerk;
    j.min_limit = a.min_limit;
    j.max_limit = a.max_limit;
    j.max_following_error = a.max_following_error;
    const config::HomingProfile& h = a.homing;
    j.home = {home_method(h.method),
              h.position,
              h.switch_position,
              h.search_velocity,
              h.latch_velocity,
              h.final_velocity > 0 ? h.final_velocity : a.max_velocity,
              h.sequence};
    if (j.home.method != HomeMethod::Immediate) s.homing_required = true;
  }
  s.interpolator = plan::Planner(machine_limits(profile), planner_config(profile)).interpolator_config();
  s.spindle_max_rpm = profile.spindle.present ? profile.spindle.max_rpm : 0.0;
  return s;
}

}  // namespace opencnc::control
