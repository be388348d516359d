// SPDX-License-Identifier: GPL-3.0-or-later
// Flame/plasma retrace's setup on a machine (docs/retrace.md): what it adds to the hub.
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/machine_setup.hpp"

namespace opencnc::retrace {

/// With [process.cutting]: the retrace feature ("retrace", following the status; its state
/// `retrace`), scanning with a source of its own made by `host`. Nothing on another machine. True
/// (it cannot fail). Before the controller runs, on the thread that sets it up.
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::retrace
