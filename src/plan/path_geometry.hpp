// SPDX-License-Identifier: GPL-3.0-or-later
// Planner geometry: programmed moves as path blocks, trimming, and corner blends within a
// tolerance (circular arcs between lines, cubic Béziers where an arc is involved).
#pragma once

#include <array>
#include <string>

#include "opencnc/canon/program.hpp"
#include "opencnc/traj/motion_block.hpp"

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

/// Blends the corner between `in` (ending at the corner) and `out` (starting there), which turns
/// by `turn`. At most `avail_in` / `avail_out` may be taken from each; the curve stays within
/// `tolerance` of the two blocks (0 = no limit) and is no larger than `need` asks. False when no
/// useful blend exists (the motion must stop).
bool blend_corner(const MotionBlock& in, double avail_in, const MotionBlock& out, double avail_out,
                  const CornerTurn& turn, double tolerance, const BlendNeed& need, Blend& result);

/// Distance from `p` to the block's curve (lines and arcs exact; others by sampling).
double distance_to(const MotionBlock& b, const Pose& p) noexcept;

}  // namespace opencnc::plan::detail
