// SPDX-License-Identifier: GPL-3.0-or-later
// Spindle-synchronised motion: G33 threading moves, G33.1 rigid tapping, G76 threading cycle.
#pragma once

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

/// Registers G33 (a straight move synchronised with the spindle, pitch K), G33.1 (rigid
/// tapping: RIGID_TAP, the machine returns to the start) and G76 (LinuxCNC's multi-pass lathe
/// threading cycle with P I J K R Q H E L) in `ext`, expanded as LinuxCNC 2.9 does.
/// Interpreter setup only (any thread before the interpreter runs); non-real-time.
void add_threading(Extensions& ext);

}  // namespace opencnc::gcode
