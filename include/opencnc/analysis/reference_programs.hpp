// SPDX-License-Identifier: GPL-3.0-or-later
// Reference programs for planner measurements, built from canonical calls: the 100 mm square,
// the dense spiral of short segments and the chain of small alternating arcs.
#pragma once

#include <cstdint>

#include "opencnc/canon/program.hpp"
#include "opencnc/canon/types.hpp"

namespace opencnc::analysis {

/// Path control of a reference program: G61, G61.1 or G64 with P and Q (mm, 0 = not given). The
/// programs set it before their first move, so that every corner has the same tolerance.
struct PathMode {
  canon::MotionControl mode = canon::MotionControl::Continuous;
  double p = 0;
  double q = 0;
};

/// G0 to the origin, then a `side` mm square at `feed` mm/min (like tools/lcnc/ngc/square_*.ngc).
canon::Program square_program(double side_mm, double feed_mm_min, PathMode mode);

/// `segments` G1 moves of 0.05–0.2 mm (pseudo-random, seeded) on an Archimedean spiral around
/// r = 50 mm shrinking 0.5 mm per turn, coordinates rounded to 0.1 µm like a 4-decimal file
/// (the shape of tools/lcnc/ngc/gen_spiral.py).
canon::Program spiral_program(int segments, double feed_mm_min, PathMode mode, std::uint32_t seed = 12345);

/// `arcs` tangent arcs of `radius` mm sweeping `sweep_deg` each, alternating G3 and G2, at `feed`.
/// With 90° they climb a staircase, with 180° they form a wave.
canon::Program small_arcs_program(int arcs, double radius_mm, double sweep_deg, double feed_mm_min,
                                  PathMode mode);

}  // namespace opencnc::analysis
