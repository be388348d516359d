// SPDX-License-Identifier: GPL-3.0-or-later
// From a machine profile to the limits and settings of the planner, and the servo's settings that
// match them (control/servo_setup.hpp has each stage's).
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/control/servo_setup.hpp"
#include "opencnc/control/shared_channels.hpp"
#include "opencnc/plan/machine_limits.hpp"
#include "opencnc/plan/planner.hpp"

namespace opencnc::controller {

/// Limits the planner plans with: of every driven axis, its velocity and acceleration less what
/// its compensation may use (config::compensation_reserve), and its jerk. Manual (hand-fed) axes
/// are not among them: nothing plans their motion. Non-real-time.
plan::MachineLimits machine_limits(const config::MachineProfile& profile);

/// The axes' own limits (the profile's, nothing reserved): what the drives' commands, with the
/// compensation, must stay within. Driven axes only. Non-real-time.
plan::MachineLimits axis_limits(const config::MachineProfile& profile);

/// Planner settings: the profile's servo period and look-ahead. Non-real-time.
plan::PlannerConfig planner_config(const config::MachineProfile& profile);

/// The servo's view of the machine. The interpolator settings are those of a planner made with
/// machine_limits() and planner_config(), so blocks and tick agree. Non-real-time.
control::ServoConfig servo_config(const config::MachineProfile& profile);

/// What a tick in another process (the HAL component) is handed for `profile`: its servo_config()
/// and the capabilities it declares wired. Non-real-time.
control::SharedSetup shared_setup(const config::MachineProfile& profile);

}  // namespace opencnc::controller
