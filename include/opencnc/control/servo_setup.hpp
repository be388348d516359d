// SPDX-License-Identifier: GPL-3.0-or-later
// From a machine profile to the settings of the servo tick: every stage's from its section (the
// joints, homing, compensation, interlocks, alarms, handwheel, load guard, power stop, coupling,
// EDM), as the fixed-size plain data the tick is handed here or in another process.
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/control/shared_channels.hpp"
#include "opencnc/traj/interpolator.hpp"

namespace opencnc::control {

/// The servo's view of the machine; `interpolator` the settings of the planner that feeds the
/// tick (controller/servo_setup.hpp gives the planner's). Non-real-time; any thread.
ServoConfig servo_config(const config::MachineProfile& profile, const traj::InterpolatorConfig& interpolator);
/// The tick's fixed-size copy of the profile's [coupling] (tables numbered from 1 in programs).
/// Non-real-time; any thread.
motion::CouplingConfig coupling_config(const config::CouplingProfile& coupling);
/// The load guard's levels from `[process.broaching]` (disabled without it). Any thread.
LoadGuardConfig load_guard_config(const config::MachineProfile& profile);

/// What a tick in another process (the HAL component) is handed: `servo` (servo_config() of the
/// profile) and what the profile declares wired (the capabilities the simulated machine of the
/// profile would have: joints and their drives, switches, index, spindle, probe, I/O counts), the
/// same bytes for the same profile. Non-real-time.
SharedSetup shared_setup(const config::MachineProfile& profile, const ServoConfig& servo);

}  // namespace opencnc::control
