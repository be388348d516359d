// SPDX-License-Identifier: GPL-3.0-or-later
// recovery::run_recovery — drives a simulated machine until the journal's recovery choice ends,
// never longer: a hold nobody will answer, a stall or a time limit ends it with the reason.
#pragma once

#include <string>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/controller/sim_rig.hpp"

namespace opencnc::recovery {

/// Bounds of the wait.
struct RecoveryWait {
  double max_s = 4 * 3600.0;  ///< servo time at most
  double stall_s = 2.0;       ///< no job running and the choice not ended this long: it never will
};

/// Steps `rig` until the choice the journal accepted has completed or failed. A feed hold (the
/// load guard: nobody here resumes it) or a fault aborts the job, which ends the choice as failed;
/// a stall or `wait.max_s` ends the wait. Returns "" when it completed, otherwise why not (the
/// journal's error, the load at the hold, the fault). The thread that drives `rig`.
std::string run_recovery(controller::SimRig& rig, const BreakpointJournal& journal, RecoveryWait wait = {});

}  // namespace opencnc::recovery
