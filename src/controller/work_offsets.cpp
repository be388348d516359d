// SPDX-License-Identifier: GPL-3.0-or-later
// Work coordinates from machine coordinates: the program builder's transform, inverted.
#include <cmath>
#include <numbers>

#include "opencnc/controller/controller_status.hpp"

namespace opencnc::controller {

const char* work_system_name(std::uint8_t system) noexcept {
  static constexpr const char* kNames[] = {"G54", "G55",   "G56",   "G57",  "G58",
                                           "G59", "G59.1", "G59.2", "G59.3"};
  return system >= 1 && system <= 9 ? kNames[system - 1] : "";
}

// canon::ProgramBuilder: machine = rotate_xy(work·scale + g92) + (g5x + tool). The same sums are
// undone in the reverse order, so that an offset with no rotation shows up exactly.
Pose work_position(const Pose& machine, const WorkOffsets& o) noexcept {
  Pose p;
  for (int i = 0; i < kAxisCount; ++i) p[i] = machine[i] - (o.g5x[i] + o.tool[i]);
  if (o.xy_rotation_deg != 0) {
    const double r = -o.xy_rotation_deg * std::numbers::pi / 180.0;
    const double x = p[0], y = p[1];
    p[0] = x * std::cos(r) - y * std::sin(r);
    p[1] = x * std::sin(r) + y * std::cos(r);
  }
  for (int i = 0; i < kAxisCount; ++i) p[i] -= o.g92[i];
  return p;
}

}  // namespace opencnc::controller
