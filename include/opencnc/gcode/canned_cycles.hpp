// SPDX-License-Identifier: GPL-3.0-or-later
// Canned cycles G73 G74 G81-G89 (drilling, peck drilling, tapping, boring) for the interpreter.
#pragma once

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

/// Registers the canned-cycle handlers (G73 G74 G81 G82 G83 G84 G85 G86 G87 G88 G89) in `ext`.
/// They expand each cycle block into canonical moves as LinuxCNC 2.9 does: R plane and
/// initial level, G98/G99 retract, L repeats, G91 increments, sticky R/Z/P/Q/I/J/K words,
/// every plane (G17-G19, G17.1-G19.1). Their words persist in InterpState::cycle.
/// Interpreter setup only (any thread before the interpreter runs); non-real-time.
void add_canned_cycles(Extensions& ext);

}  // namespace opencnc::gcode
