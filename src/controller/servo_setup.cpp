// SPDX-License-Identifier: GPL-3.0-or-later
// Profile → planner limits and planner settings, and the servo's settings that match them.
#include "opencnc/controller/servo_setup.hpp"

#include <algorithm>

namespace opencnc::controller {

namespace {

plan::MachineLimits limits(const config::MachineProfile& profile, bool reserve) {
  plan::MachineLimits m;
  m.axes = AxisMask{};
  for (const config::AxisProfile& a : profile.axes) {
    if (a.manual()) continue;
    m.axes.set(a.axis);
    const config::MotionReserve r =
        reserve ? config::compensation_reserve(a, profile.servo_period_s) : config::MotionReserve{};
    m.axis[static_cast<std::size_t>(index(a.axis))] = {a.max_velocity - r.velocity,
                                                       a.max_acceleration - r.acceleration, a.max_jerk};
  }
  return m;
}

}  // namespace

plan::MachineLimits machine_limits(const config::MachineProfile& profile) {
  return limits(profile, true);
}

plan::MachineLimits axis_limits(const config::MachineProfile& profile) {
  return limits(profile, false);
}

plan::PlannerConfig planner_config(const config::MachineProfile& profile) {
  plan::PlannerConfig c;
  c.servo_period_s = profile.servo_period_s;
  c.lookahead_moves = static_cast<std::size_t>(std::max(2, profile.planner.lookahead));
  return c;
}

control::ServoConfig servo_config(const config::MachineProfile& profile) {
  return control::servo_config(
      profile, plan::Planner(machine_limits(profile), planner_config(profile)).interpolator_config());
}

control::SharedSetup shared_setup(const config::MachineProfile& profile) {
  return control::shared_setup(profile, controller::servo_config(profile));
}

}  // namespace opencnc::controller
