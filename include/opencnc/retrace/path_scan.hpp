// SPDX-License-Identifier: GPL-3.0-or-later
// Building a PathIndex from a program file: the controller's own preflight scan (the interpreter
// in scan mode with the machine's dialect, modules, tool table and subroutine path), every move
// as it will execute — subprograms, loops, jumps, Fanuc calls, kerf compensation applied.
#pragma once

#include <string>

#include "opencnc/controller/program_source.hpp"
#include "opencnc/retrace/path_index.hpp"

namespace opencnc::recovery {

/// The index of `path` run from `start` (machine coordinates), with the problems the scan met
/// in `diags` (an index of a program with errors holds the moves before the first one).
/// Non-real-time; call on a thread of its own for a large program (`source` is used only by it).
PathIndex scan_path(controller::ProgramSource& source, const std::string& path, const Pose& start,
                    const controller::LoadOptions& options, Diagnostics& diags);

}  // namespace opencnc::recovery
