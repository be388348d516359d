// SPDX-License-Identifier: GPL-3.0-or-later
// The geometry of one feed move of the path index: a line or a circular arc/helix in X Y Z, its
// bounding box, its point at a parameter, and the nearest point to a query in XY or in space.
#pragma once

#include <cstdint>

#include "opencnc/canon/program.hpp"
#include "opencnc/retrace/path_index.hpp"

namespace opencnc::recovery::detail {

inline constexpr std::uint32_t kNoArc = 0xffffffffu;

/// An arc or helix as the machine runs it: p(t) = c + r·(cos θ·e1 + sin θ·e2) + t·rest with
/// θ = t·sweep (signed: negative is clockwise about e1 × e2), t ∈ [0, 1].
struct ArcShape {
  Vec3 c{}, e1{}, e2{}, rest{};
  double r = 0, sweep = 0;
  bool circle_xy = false;   ///< seen from above it is a circular arc (normal ∥ Z, no XY drift)
  bool circle_xyz = false;  ///< a plane circular arc (no rise)
};

/// One feed move (72 bytes).
struct Shape {
  Vec3 a{}, b{};               // start and end, X Y Z
  std::uint64_t move = 0;      // the move's number in the scan
  std::uint32_t arc = kNoArc;  // index into the arcs
  std::uint32_t entry = 0;     // path order among the feed moves
  std::uint32_t context = 0, line = 0;
};

/// Axis-aligned box.
struct Box {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  void add(const Vec3& p) noexcept {
    for (int i = 0; i < 3; ++i) {
      lo[i] = p[i] < lo[i] ? p[i] : lo[i];
      hi[i] = p[i] > hi[i] ? p[i] : hi[i];
    }
  }
  void add(const Box& o) noexcept {
    add(o.lo);
    add(o.hi);
  }
};

/// The arc of move `move` of `p` from its start to its end (the centre moved onto the bisector
/// of the end points, as the planner does, so both ends lie on the circle). False for a
/// degenerate arc (radius zero): it is indexed as a line.
bool make_arc_shape(const canon::Program& p, std::size_t move, ArcShape& out);

/// The point at parameter t ∈ [0, 1].
Vec3 point_at(const Shape& s, const ArcShape* arc, double t) noexcept;
/// The bounding box (conservative for arcs: the whole circle's box widened by the rise).
Box bounds(const Shape& s, const ArcShape* arc) noexcept;
/// Length along the path, mm.
double length(const Shape& s, const ArcShape* arc) noexcept;

/// The nearest point of the move to `q`: its parameter and squared distance in `metric`.
struct Closest {
  double t = 0;
  double d2 = 0;
};
Closest closest(const Shape& s, const ArcShape* arc, const Vec3& q, Metric metric) noexcept;

}  // namespace opencnc::recovery::detail
