// SPDX-License-Identifier: GPL-3.0-or-later
// NURBS curves as LinuxCNC's NURBS_FEED defines them: evaluation, and splitting into chords
// that stay within a tolerance of the curve (for moves the planner can run).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "opencnc/canon/types.hpp"

namespace opencnc::canon {

/// LinuxCNC's knot vector for `count` control points of order `order` (degree order - 1):
/// clamped and uniform with whole-number knots, `order` zeros, then 1, 2, ..., then
/// count - order + 1 repeated `order` times. The curve runs for u in [0, knots.back()].
/// Any thread.
std::vector<double> nurbs_knots(std::size_t count, int order);

/// A point of the curve and its parameter.
struct CurvePoint {
  double x = 0, y = 0;
  double u = 0;
};

/// The point at parameter `u` (clamped to the knot range) by de Boor's algorithm in
/// homogeneous coordinates. Needs 2 <= order <= points.size() and a non-zero weighted sum
/// at u. Any thread.
CurvePoint nurbs_point(std::span<const NurbsPoint> points, int order, double u);

/// Splits the curve into chords and returns their ends in order (the first chord starts at
/// the first control point, where the curve starts, at u = 0). Every point of the curve lies
/// within `tolerance` of the chord of its parameter interval (from the previous vertex's u to
/// this one's), and the last vertex is exactly the last control point.
///
/// How: the blossom of each knot span gives its rational Bezier piece; de Casteljau halves a
/// piece until all its control points lie within `tolerance` of the chord between its ends.
/// With positive weights a rational Bezier piece lies in the convex hull of its control
/// points, and every point of that hull is within `tolerance` of the chord, which bounds
/// the error. Weights that are not all positive (LinuxCNC accepts a first G5.2 point with no
/// P, weight -1) give no such bound; the control polygon is returned then, as it is for
/// orders outside 2..min(64, points.size()). O(points · order³). Non-real-time (allocates);
/// any thread.
std::vector<CurvePoint> tessellate_nurbs(std::span<const NurbsPoint> points, int order, double tolerance);

}  // namespace opencnc::canon
