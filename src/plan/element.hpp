// SPDX-License-Identifier: GPL-3.0-or-later
// Element — a programmed move (or what stands for several) as the planner's corner stage takes it.
#pragma once

#include "opencnc/canon/types.hpp"
#include "opencnc/traj/motion_block.hpp"

namespace opencnc::plan::detail {

/// A programmed move (or a merged run of them) ready for corner processing.
struct Element {
  traj::MotionBlock b;         ///< geometry, identity, class, flags, nominal speed
  double orig_length = 0;      ///< length before any blend trimmed it
  double merge_deviation = 0;  ///< how far it may lie from the programmed moves (G64 Q merge, fitted run)
  canon::MotionControl mode = canon::MotionControl::Continuous;  ///< for the corner at its end
  double tolerance = 0;                                          ///< G64 P (mm), 0 = none
  bool stop_after = false;  ///< the motion must stop at its end (probe moves)
  double junction = 0;      ///< speed limit where it starts (0: from rest, +∞: none)
};

}  // namespace opencnc::plan::detail
