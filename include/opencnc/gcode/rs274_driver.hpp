// SPDX-License-Identifier: GPL-3.0-or-later
// A run shaped like LinuxCNC's stand-alone `rs274 -g` (its driver's resets included), so that
// `opencnc canon` output can be compared with rs274's line for line.
#pragma once

#include <functional>

#include "opencnc/canon/rs274_printer.hpp"
#include "opencnc/gcode/interpreter.hpp"

namespace opencnc::gcode {

/// How the program itself is run (default: Interpreter::run; the command line's shows progress).
using RunFunction = std::function<RunStatus(Interpreter&, canon::Sink&)>;

/// Runs `interp` to its end printing on `printer` as `rs274 -g` does: the start-up calls,
/// one ON_RESET, the program (through `run` if given), then two ON_RESETs (also after an
/// error). Returns the run's status. Interpreter thread; non-real-time.
RunStatus run_like_rs274(Interpreter& interp, canon::Rs274Printer& printer, const RunFunction& run = {});

}  // namespace opencnc::gcode
