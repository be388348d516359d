// SPDX-License-Identifier: GPL-3.0-or-later
// The geometry words of arcs every layer shares: a plane's axes, its axis triple, the sweep of an
// arc from LinuxCNC's turn count.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "opencnc/canon/types.hpp"

namespace opencnc::canon {

/// The axis indices of a plane: the first and second axes of its circles and the normal, with
/// first × second = +normal (G17: X Y Z, G18: Z X Y, G19: Y Z X; the UVW planes alike).
struct PlaneAxes {
  int first = 0, second = 1, normal = 2;
};

constexpr PlaneAxes plane_axes(Plane p) noexcept {
  switch (p) {
    case Plane::XY:
      return {0, 1, 2};
    case Plane::YZ:
      return {1, 2, 0};
    case Plane::XZ:
      return {2, 0, 1};
    case Plane::UV:
      return {6, 7, 8};
    case Plane::VW:
      return {7, 8, 6};
    case Plane::UW:
      return {8, 6, 7};
  }
  return {};
}

/// The first axis of the plane's triple: 0 for the X Y Z planes, 6 for the U V W planes (an
/// ArcGeometry's centre and normal are in that triple).
constexpr int plane_base(Plane p) noexcept {
  return p == Plane::XY || p == Plane::YZ || p == Plane::XZ ? 0 : 6;
}

/// "XY", "YZ", "XZ", "UV", "VW", "UW".
constexpr const char* plane_name(Plane p) noexcept {
  switch (p) {
    case Plane::XY:
      return "XY";
    case Plane::YZ:
      return "YZ";
    case Plane::XZ:
      return "XZ";
    case Plane::UV:
      return "UV";
    case Plane::VW:
      return "VW";
    case Plane::UW:
      return "UW";
  }
  return "?";
}

/// The signed sweep (radians, + counterclockwise about the normal) of an arc whose end lies at
/// angle `phi` ∈ (−π, π] from its start, with LinuxCNC's turn count `turns` (its sign the
/// direction, 0 taken as 1): an end on the start is a whole circle, and |turns| − 1 extra full
/// circles are added. Real-time safe.
inline double arc_sweep(double phi, int turns) noexcept {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  const bool ccw = turns >= 0;
  const bool full = std::fabs(phi) < 1e-9;  // end on start: a whole circle
  const double s = ccw ? (full ? kTwoPi : (phi > 0 ? phi : phi + kTwoPi))
                       : (full ? -kTwoPi : (phi < 0 ? phi : phi - kTwoPi));
  const int extra = std::max(0, std::abs(turns) - 1);
  return s + (ccw ? 1.0 : -1.0) * kTwoPi * extra;
}

}  // namespace opencnc::canon
