// SPDX-License-Identifier: GPL-3.0-or-later
// The plasma cutting feature on a machine: its codes, its holes pass, its texts, its recorder and
// its state, added to the hub through its extension points (docs/cutting.md).
#pragma once

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/machine_setup.hpp"

namespace opencnc::cutting {

/// With [process.plasma]: the torch's codes M190–M193, the holes pass ([process.plasma.holes]
/// with a diameter), the torch stage's events in words, the torch's state for a front end
/// (`cutting`), and for a front end that writes reports the recorder (CuttingRecorder: the
/// report's `cutting`), and with `[cut_chart]` the cut chart's codes and checks (cut_chart.hpp).
/// Nothing on another machine. False (the reason in `host.diagnostics()`) only when the cut chart
/// cannot be opened. Before the controller runs, on the thread that sets it up.
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::cutting
