// SPDX-License-Identifier: GPL-3.0-or-later
// A point turned about a rotary axis' line in space (Rodrigues' formula): what a table on B
// does to what is mounted on it.
#pragma once

#include <cmath>

#include "opencnc/core/vec3.hpp"

namespace opencnc::machine {

/// `p` turned by `angle_rad` about the line through `on_axis` along the unit vector `direction`,
/// right-handed (about +Y: +Z toward +X). Any thread; real-time safe.
inline Vec3 rotate_about(const Vec3& p, const Vec3& on_axis, const Vec3& direction,
                         double angle_rad) noexcept {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  const Vec3 v = p - on_axis;
  const Vec3& d = direction;
  const Vec3 across = cross(d, v);
  const double along = dot(d, v) * (1 - c);
  Vec3 out{};
  for (int i = 0; i < 3; ++i) out[i] = on_axis[i] + v[i] * c + across[i] * s + d[i] * along;
  return out;
}

}  // namespace opencnc::machine
