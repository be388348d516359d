// SPDX-License-Identifier: GPL-3.0-or-later
// The drill retrofit's setup on a machine (docs/machine.md): what its hand-fed axes add to the hub.
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/machine_setup.hpp"

namespace opencnc::drill {

/// The hand-fed axes' parts on `host` for a profile with manual axes: the pass that turns their
/// programmed moves into waits for the operator (hand_axis.hpp), their wait and their event (an
/// axis that left where the program needs it) in words. Nothing on another machine. True (it
/// cannot fail). Before the controller runs, on the thread that sets it up.
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::drill
