// SPDX-License-Identifier: GPL-3.0-or-later
// Helical broaching's setup on a machine (docs/broaching.md): what it adds to the hub.
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/machine_setup.hpp"

namespace opencnc::broaching {

/// Broaching's parts on `host`. With [coupling]: the codes M171-M175 and the coupling pass (the
/// slave's coordinates by the law, its limits through it), the coupling's wait and fault in words.
/// With [process.broaching]: the load guard's events in words. With a power monitor ([power]
/// monitor) and a journal folder (the front end's setting "journal"): the breakpoint journal
/// ("journal", following the status and the trace; its state `journal`), its sources made by
/// `host`. False with the reasons in host.diagnostics() (a journal folder that cannot be opened).
/// Before the controller runs, on the thread that sets it up.
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::broaching
