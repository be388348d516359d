// SPDX-License-Identifier: GPL-3.0-or-later
// A move's path length as the planner parameterises it, and where a path offset counted from one
// move's start lies when the planner ran that move and the ones after it as one block.
#pragma once

#include "opencnc/canon/program.hpp"

namespace opencnc::canon {

/// Path length of move `id` (held in `p`): a straight move's Euclidean length over every axis (a
/// coupled C's degrees included, as the planner counts them), an arc's or helix's sweep times its
/// radius with the rise.
double planned_length(const Program& p, SegmentId id);

/// A move and a path offset from its start.
struct MoveOffset {
  SegmentId move = 0;
  double offset_mm = 0;
};

/// Where `offset_mm` from the start of `move` lies, counted on into the moves that follow it: the
/// planner joins a run of lines of one feed into one block (G64 Q, the naive-CAM tolerance) and
/// reports the offset from the run's first move. Goes on only over feed moves (lines, arcs) held
/// in `p`; an offset within the move, or a move followed by anything else, stays where it is.
MoveOffset along_joined(const Program& p, SegmentId move, double offset_mm);

}  // namespace opencnc::canon
