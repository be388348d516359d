// SPDX-License-Identifier: GPL-3.0-or-later
// Planner geometry: programmed moves as path blocks, trimming, and corner blends within a
// tolerance (circular arcs between lines, cubic Béziers where an arc is involved).
#pragma once

#include <algorithm>
#include <array>
#include <string>

#include "opencnc/canon/program.hpp"
#include "opencnc/traj/motion_block.hpp"
#include "opencnc/traj/path_eval.hpp"
#include "vec.hpp"

namespace opencnc::plan::detail {

using traj::MotionBlock;

/// Corners turning by less than this (radians) are treated as tangent.
inline constexpr double kTangentAngle = 1e-9;
/// Corners turning by more than this are reversals: no blend, the motion stops.
inline constexpr double kReversalAngle = 3.14159265358979323846 - 1e-6;
/// Path pieces shorter than this (s-units) are dropped.
inline constexpr double kMinLength = 1e-9;

/// Straight block from `a` to `b`; false when shorter than kMinLength.
bool make_line(const Pose& a, const Pose& b, MotionBlock& out) noexcept;

/// Arcs smaller than this radius at both ends (mm) are their chords (a line block, or nothing).
inline constexpr double kPointArcMm = 1e-6;

/// Arc or helix block from the program's arc geometry. Where the end lies off the start circle
/// within LinuxCNC's tolerance the block is a spiral (make_spiral); radii equal up to rounding
/// keep a circle, its centre moved onto the perpendicular bisector of the end points. On bad
/// geometry returns false with a reason in `error`; false with no reason: a point-sized arc with
/// no length, nothing to move.
bool make_arc(const Pose& start, const Pose& end, const canon::ArcGeometry& arc, MotionBlock& out,
              std::string& error);
/// Spiral block about the arc's centre from radius `r0` at `start` to `r1` at `end`.
bool make_spiral(const Pose& start, const Pose& end, const canon::ArcGeometry& arc, double r0, double r1,
                 MotionBlock& out);

/// Length over which the feed rate applies (XYZ, else UVW, else ABC) divided by the block length.
double feed_length_ratio(const Pose& start, const Pose& end, const MotionBlock& b) noexcept;

/// Removes the first / last `d` units of s from a line or arc block.
void trim_start(MotionBlock& b, double d) noexcept;
void trim_end(MotionBlock& b, double d) noexcept;
/// Moves the start of `b` onto `p` (the previous block's exact end), keeping its end.
void rebase(MotionBlock& b, const Pose& p) noexcept;

Pose end_point(const MotionBlock& b) noexcept;
Pose end_tangent(const MotionBlock& b) noexcept;
Pose start_tangent(const MotionBlock& b) noexcept;

/// A corner blend: the curve, and how much it takes from the end of the incoming block and
/// the start of the outgoing one.
struct Blend {
  MotionBlock curve;
  double trim_in = 0, trim_out = 0;
};

/// How big a blend needs to be: no larger than what lets the corner be taken at `speed` with the
/// centripetal acceleration within `share` × `accel[i]` on every axis.
struct BlendNeed {
  double speed = 0;
  double share = 0.95;
  std::array<double, kAxisCount> accel{};
};

/// The directions at a corner: unit tangents at the end of the incoming block and the start of
/// the outgoing one, the angle θ between them and sin(θ/2) (half the chord between the tangents).
struct CornerTurn {
  Pose in{}, out{};
  double angle = 0;
  double half_sine = 0;
};
CornerTurn corner_turn(const MotionBlock& in, const MotionBlock& out) noexcept;
/// How much |dp/ds| differs where `in` ends and `out` starts, and whether that is rounding: else
/// a tangent junction steps the axis velocities by v times the difference.
double speed_scale_step(const MotionBlock& in, const MotionBlock& out) noexcept;
bool same_speed_scale(const MotionBlock& in, const MotionBlock& out) noexcept;
/// A step of |dp/ds| no larger than this is passed without a transition where no blend is
/// allowed (the 0.1 % a spiral's |dp/ds| may differ from 1: LinuxCNC's tolerance on arc radii).
inline constexpr double kSpeedScaleSlack = 1e-3;

/// Blends the corner between `in` (ending at the corner) and `out` (starting there), which turns
/// by `turn` (or, tangent, where |dp/ds| differs: a transition between them). At most `avail_in` /
/// `avail_out` may be taken from each; the curve stays within `tolerance` of the two blocks (0 = no limit)
/// and is no larger than `need` asks. False when no useful blend exists (the motion must stop).
bool blend_corner(const MotionBlock& in, double avail_in, const MotionBlock& out, double avail_out,
                  const CornerTurn& turn, double tolerance, const BlendNeed& need, Blend& result);

/// Distance from `p` to the block's curve (lines and arcs exact; others by sampling).
double distance_to(const MotionBlock& b, const Pose& p) noexcept;

/// A point of a path block with the first and second derivative there (dp/ds, d²p/ds²): what a
/// curvature-continuous (G2) blend must match to keep every axis's acceleration continuous.
struct JoinPoint {
  Pose p{}, d1{}, d2{};
};
JoinPoint join_at(const MotionBlock& b, double s) noexcept;

/// The quintic Bézier from `a` to `b` whose position, dp/ds and d²p/ds² at both ends are those of
/// the join points, parameterised by its own length (so that |dp/ds| is about 1 all along):
/// control points P0 = a.p, P1 = P0 + L/5·a.d1, P2 = 2P1 − P0 + L²/20·a.d2 and the mirror
/// image at the end, L the fixed point of L = arc length(L). False when it has no such length or
/// stops (a cusp). The caller sets identity, class and feed.
bool make_g2_curve(const JoinPoint& a, const JoinPoint& b, MotionBlock& out) noexcept;

/// Whether every point of the cubic or quintic Bézier `c` lies within `tolerance` of a path,
/// `distance(p)` giving a point's distance to it. The distance to any set is 1-Lipschitz and the
/// curve moves at most Lip·Δt in Δt (Lip = n·max|ΔP| from its control polygon), so between
/// parameters a and b the distance is at most (d_a + d_b + Lip·(b − a))/2. Intervals whose bound
/// exceeds the tolerance are halved until it holds, or a sample exceeds it (branch and bound: the
/// work follows how close the curve comes); "no" when too close to decide. The start point is
/// not checked (curves start on the path). Non-real-time.
template <typename Distance>
bool curve_within(const MotionBlock& c, Distance&& distance, double tolerance) noexcept {
  const int n = c.kind == traj::BlockKind::Quintic ? 5 : 3;
  const Pose q[6] = {c.base, c.u, c.w, c.lin, c.p4, c.p5};
  double lip = 0;
  for (int k = 0; k < n; ++k) lip = std::max(lip, norm(q[k + 1] - q[k]));
  lip *= n;
  const auto dist = [&](double t) { return distance(traj::position_at(c, c.length * t)); };
  constexpr int kStart = 16, kMaxSamples = 4096, kDepth = 64;
  struct Span {
    double a, b, da, db;
  };
  Span stack[kDepth];
  int top = 0, samples = kStart + 1;
  double da = dist(0.0);
  for (int k = 1; k <= kStart; ++k) {
    const double t0 = static_cast<double>(k - 1) / kStart, t1 = static_cast<double>(k) / kStart;
    const double db = dist(t1);
    if (db > tolerance) return false;
    stack[top++] = {t0, t1, da, db};
    while (top > 0) {
      const Span s = stack[--top];
      if (0.5 * (s.da + s.db + lip * (s.b - s.a)) <= tolerance) continue;
      if (top + 2 > kDepth || ++samples > kMaxSamples) return false;  // too close to call: not within
      const double m = 0.5 * (s.a + s.b), dm = dist(m);
      if (dm > tolerance) return false;
      stack[top++] = {m, s.b, dm, s.db};
      stack[top++] = {s.a, m, s.da, dm};
    }
    da = db;
  }
  return true;
}

/// Distance from `v` to a point of the Bézier `c` near the nearest one (sampled, then refined): at
/// least the distance from `v` to the curve, and equal to it up to the search's resolution.
/// Non-real-time.
double point_to_curve(const MotionBlock& c, const Pose& v) noexcept;

/// Whether every point of the quintic `c` lies within `tolerance` of the nearer of `in` and
/// `out` (curve_within), and the corner where they meet (the end of `in`) within `tolerance` of
/// the curve (point_to_curve): the blend neither strays from the moves nor cuts the corner off.
/// Non-real-time.
bool blend_within(const MotionBlock& c, const MotionBlock& in, const MotionBlock& out,
                  double tolerance) noexcept;

}  // namespace opencnc::plan::detail
