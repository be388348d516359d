// SPDX-License-Identifier: GPL-3.0-or-later
// Straight probing G38.2 G38.3 G38.4 G38.5 and the probe result parameters #5061-#5070.
#pragma once

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

/// The distance LinuxCNC's stand-alone interpreter backs off from the probe point towards the
/// start after a probe move: 0.01 inch, or 0.254 mm in a G21 program. Any thread; real-time safe.
constexpr double probe_backoff(canon::Units units) noexcept { return units == canon::Units::Mm ? 0.254 : 0.01; }

/// Registers G38.2-G38.5 in `ext`: TURN_PROBE_ON, STRAIGHT_PROBE, TURN_PROBE_OFF, then a
/// sync point. Execute mode: the run stops until Interpreter::sync() reports where the probe
/// tripped (#5061-#5069), whether it did (#5070) and where the machine stands; a G38.2/G38.4
/// that reports no contact ends the run with `gcode.probe-no-contact`. Scan mode: what rs274
/// assumes (the probe point is the programmed end, #5070 = 0, the tool backs off by
/// probe_backoff() towards the start). Interpreter setup only; non-real-time.
void add_probing(Extensions& ext);

}  // namespace opencnc::gcode
