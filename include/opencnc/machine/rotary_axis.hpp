// SPDX-License-Identifier: GPL-3.0-or-later
// A point turned about a rotary axis' line in space (Rodrigues' formula): what a table on B
// does to what is mounted on it.
#pragma once

#include <array>
#include <cmath>

namespace opencnc::machine {

/// `p` turned by `angle_rad` about the line through `on_axis` along the unit vector `direction`,
/// right-handed (about +Y: +Z toward +X). Any thread; real-time safe.
inline std::array<double, 3> rotate_about(const std::array<double, 3>& p,
                                          const std::array<double, 3>& on_axis,
                                          const std::array<double, 3>& direction, double angle_rad) noexcept {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  const std::array<double, 3> v{p[0] - on_axis[0], p[1] - on_axis[1], p[2] - on_axis[2]};
  const std::array<double, 3>& d = direction;
  const std::array<double, 3> cross{d[1] * v[2] - d[2] * v[1], d[2] * v[0] - d[0] * v[2],
                                    d[0] * v[1] - d[1] * v[0]};
  const double along = (d[0] * v[0] + d[1] * v[1] + d[2] * v[2]) * (1 - c);
  std::array<double, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) out[i] = on_axis[i] + v[i] * c + cross[i] * s + d[i] * along;
  return out;
}

}  // namespace opencnc::machine
