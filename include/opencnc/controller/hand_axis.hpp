// SPDX-License-Identifier: GPL-3.0-or-later
// The hand-axis pass: a program for a machine with hand-fed axes (the drill's quill) in which
// every programmed motion of such an axis has become a wait for the operator.
#pragma once

#include <array>
#include <memory>

#include "opencnc/canon/program.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::control {

/// The hand-fed axes of a machine and what the pass checks against.
struct HandAxes {
  AxisMask axes;
  std::array<double, kAxisCount> min_limit{}, max_limit{};
  bool any() const noexcept { return axes.bits() != 0; }
};

/// The manual axes of `profile`. Any thread.
HandAxes hand_axes(const config::MachineProfile& profile);

/// A copy of `program` whose moves never change a hand axis: each move keeps its number, its hand
/// coordinates are those of the program's start (nothing commands them), and where it moved a
/// hand axis to h a HandAxisWait action stands instead — the servo waits there until the operator
/// has brought the axis to h (moving in +, a retract: at or above h less the axis' tolerance;
/// moving in −, a plunge: down to h plus the tolerance), and then holds the run while the axis
/// leaves h (control::HandWait). A move that also moves driven axes is split by
/// safety: a retract is waited for before the table moves, a plunge after it. Arcs, probes and
/// spindle-synchronised moves cannot move a hand axis, and a target beyond the axis' soft limits
/// is refused: both are errors at the move's line (code control.hand-axis). Without hand axes
/// the program itself is returned. Non-real-time; O(size).
std::shared_ptr<const canon::Program> hand_axis_program(std::shared_ptr<const canon::Program> program,
                                                        const HandAxes& hand, Diagnostics& diags);

}  // namespace opencnc::control
