// SPDX-License-Identifier: GPL-3.0-or-later
// B's axis of rotation from the reference sphere's centres measured at several B angles: a plane
// and a least-squares circle through them (electrode setting's calibrate-b).
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/core/vec3.hpp"

namespace opencnc::edm {

/// A rotary axis as a line: where it crosses the plane Y = the sphere's centre (X, Z) and its
/// unit direction (+B right-handed about it).
struct BAxisLine {
  std::array<double, 2> crossing{};  ///< X, Z, mm
  Vec3 direction{0, 1, 0};
};

/// What the fit found.
struct BAxisFit {
  BAxisLine axis;
  double radius_mm = 0;  ///< of the circle the centres lie on (the sphere's distance from the axis)
  /// Per angle: the measured centre's distance from where the fitted axis turns the sphere to.
  std::vector<double> residuals_mm;
  double rms_residual_mm = 0, max_residual_mm = 0;
};

/// The axis from `centres[k]`, the fitted centres of the sphere (plus the measuring electrode's
/// offsets, the same at every angle) with B at `angles_deg[k]`: the plane of least squares
/// through them (its normal is the direction, oriented so that B turns right-handed about it),
/// the circle of least squares in that plane (algebraic start, then geometric Gauss–Newton; its
/// centre is on the axis), and the line moved by the electrode's offsets, which are the centre at
/// `sphere.b_deg` less `sphere.position` (the profile's position holds at b, so an electrode that
/// is off its table entry does not move the axis). Nothing when fewer than three distinct angles
/// are given, the centres are (nearly) one point or on a line, or the axis lies along the plane.
/// Any thread; not real-time.
std::optional<BAxisFit> fit_b_axis(std::span<const double> angles_deg, std::span<const Vec3> centres,
                                   const config::ReferenceSphereProfile& sphere);

/// The sphere's centre with B at `b_deg`: `position` turned about the profile's `b_axis` by
/// b_deg − b. Without a b_axis, `position` (only right at b). Any thread.
Vec3 sphere_centre_at(const config::ReferenceSphereProfile& sphere, double b_deg);

}  // namespace opencnc::edm
