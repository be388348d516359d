// SPDX-License-Identifier: GPL-3.0-or-later
// Comments: what a block's comment does — a message, a print or log line, an abort, or a plain
// comment passed on (comments.cpp).
#pragma once

#include <string_view>

namespace opencnc::gcode {

struct InterpState;
class ParameterHost;
class Output;

/// Acts on a block's comment: (MSG,) (DEBUG,) (PRINT,) (LOG*,) (ABORT,) with the parameter
/// values of `st` and `params` substituted where LinuxCNC substitutes them; others go to `out`
/// as comments. Throws GcodeError for (ABORT,) and embedded Python. Interpreter thread.
void convert_comment(std::string_view comment, const InterpState& st, ParameterHost& params, Output& out);

}  // namespace opencnc::gcode
