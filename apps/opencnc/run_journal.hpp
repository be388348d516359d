// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc run --journal DIR`: the breakpoint journal's writer on the run's controller, and what it
// wrote in the report.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/recovery/breakpoint_journal.hpp"

namespace opencnc::cli {

/// The journal feature writing into `dir` (created if missing), with the profile's interpreter
/// options for the modal digest; nullptr after printing why. CLI thread, before the run.
std::shared_ptr<recovery::BreakpointJournal> open_run_journal(const std::string& dir,
                                                              const config::MachineProfile& profile);

/// Waits for the writer, prints what the journal holds and returns it as the report's `journal`:
/// `written`, `valid`, `stage`, `segment`, `line`, `file`, `segment_offset_mm`,
/// `move_remaining_mm`, `program_hash` (hex), `modal_digest` (hex), `record_latency_ms`, `error`.
/// With a record written and `sim_bore` not empty (the simulated broach's workpiece), keeps the
/// bore beside it in `dir` (recovery::save_sim_bore) for `opencnc recover`; `sim_bore` in the report.
nlohmann::json finish_run_journal(recovery::BreakpointJournal& journal, const std::string& dir,
                                  const std::vector<float>& sim_bore);

}  // namespace opencnc::cli
