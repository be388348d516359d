// SPDX-License-Identifier: GPL-3.0-or-later
// Run from line's setup on a machine (docs/hmi.md, "Run from line"): what it adds to the hub.
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/machine_setup.hpp"

namespace opencnc::run_from_line {

/// On every machine: the run-from-line feature ("run-from-line", following the status), scanning
/// with a source of its own made by `host` whose tool table is the controller's with the scan's
/// G10 writes kept apart. True (it cannot fail). Before the controller runs, on the thread that
/// sets it up.
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::run_from_line
