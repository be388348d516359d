// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc run --journal DIR`: the breakpoint journal's writer on the run's controller, and what it
// wrote in the report.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/config/machine_profile.hpp"

namespace opencnc::cli {

/// Waits for the writer, prints what the journal holds and returns it as the report's `journal`:
/// `written`, `valid`, `stage`, `segment`, `line`, `file`, `segment_offset_mm`,
/// `move_remaining_mm`, `program_hash` (hex), `modal_digest` (hex), `record_latency_ms`, `error`.
/// With a record written and `sim_bore` not empty (the simulated broach's workpiece), keeps the
/// bore beside it in `dir` (recovery::save_sim_bore) for `opencnc recover`; `sim_bore` in the report.
nlohmann::json finish_run_journal(recovery::BreakpointJournal& journal, const std::string& dir,
                                  const std::vector<float>& sim_bore);

}  // namespace opencnc::cli
