// SPDX-License-Identifier: GPL-3.0-or-later
// The sinker EDM's setup on a machine (docs/edm.md): what it adds to the hub.
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/machine_setup.hpp"

namespace opencnc::edm {

/// The EDM's parts on `host`. With [edm]: the codes M180/M181 (M180's P one of the profile's
/// conditions, taken again from an edited profile), the reach of the conditions' orbits and jumps
/// in the soft-limit check, the gap servo's events and faults in words, the burn's depth in the
/// front end's state (`edm`), and for a front end that writes reports the recorder of every burn
/// (EdmRecorder: the report's `edm`). With [probe.reference_sphere] and a tool table: the
/// electrode setting ("electrode", following the status and the trace; its state `electrode`).
/// Nothing on another machine. False with the reasons in host.diagnostics(). Before the
/// controller runs, on the thread that sets it up.
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::edm
