// SPDX-License-Identifier: GPL-3.0-or-later
// Cutter radius compensation (G40, G41, G42, G41.1, G42.1) as LinuxCNC 2.9 does it.
#pragma once

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

/// Registers cutter radius compensation in `ext`: G41/G42 (radius from the tool table, D = a
/// tool number), G41.1/G42.1 (D = diameter, L = lathe tool orientation), G40, and the motion
/// stage that offsets every line and arc of the XY (G17) or XZ (G18) plane, rounds convex
/// corners, settles concave ones and reports gouges. Its state between blocks lives in
/// InterpState (modal flags, PositionState::programmed, CompState), so one registry serves
/// any number of interpreters. Any thread, while building the registry; non-real-time.
void add_cutter_compensation(Extensions& ext);

}  // namespace opencnc::gcode
