// SPDX-License-Identifier: GPL-3.0-or-later
// The LinuxCNC spline codes G5 (cubic), G5.1 (quadratic), G5.2/G5.3 (NURBS) as interpreter extensions.
#pragma once

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

/// Registers G5, G5.1, G5.2 and G5.3. Each curve leaves the interpreter as one
/// canon::Sink::nurbs_feed call (rs274's NURBS_FEED). Non-real-time.
void add_splines(Extensions& ext);

}  // namespace opencnc::gcode
