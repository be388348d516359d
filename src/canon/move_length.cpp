// SPDX-License-Identifier: GPL-3.0-or-later
// Move lengths and offsets along joined moves (canon/move_length.hpp).
#include "opencnc/canon/move_length.hpp"

#include <cmath>

#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::canon {

namespace {

/// An offset this much past a move's end is still on it (rounding of the planner's sums).
constexpr double kOnTheMoveMm = 1e-9;

double arc_length(const Program& p, SegmentId id) {
  const ArcGeometry& g = p.arc(id);
  const int base = plane_base(g.plane);
  const Vec3& n = g.normal;
  Vec3 u = take3(p.start_of(id), base) - g.center, w = take3(p.end(id), base) - g.center;
  const double un = dot(u, n), wn = dot(w, n);
  u = u - un * n;
  w = w - wn * n;
  const double sweep = arc_sweep(std::atan2(dot(cross(u, w), n), dot(u, w)), g.turns);
  return std::hypot(norm(u) * std::fabs(sweep), wn - un);
}

}  // namespace

double planned_length(const Program& p, SegmentId id) {
  if (p.move(id).kind == MoveKind::Arc) return arc_length(p, id);
  const Pose a = p.start_of(id), b = p.end(id);
  double sum = 0;
  for (std::size_t i = 0; i < a.v.size(); ++i) sum += (b.v[i] - a.v[i]) * (b.v[i] - a.v[i]);
  return std::sqrt(sum);
}

MoveOffset along_joined(const Program& p, SegmentId move, double offset_mm) {
  MoveOffset at{move, offset_mm};
  const auto feed = [&](SegmentId id) {
    const MoveKind k = p.move(id).kind;
    return k == MoveKind::Feed || k == MoveKind::Arc;
  };
  if (move < p.first_held_move() || move >= p.size() || !feed(move)) return at;
  for (;;) {
    const double length = planned_length(p, at.move);
    if (at.offset_mm <= length + kOnTheMoveMm || at.move + 1 >= p.size() || !feed(at.move + 1)) return at;
    at.offset_mm -= length;
    ++at.move;
  }
}

}  // namespace opencnc::canon
