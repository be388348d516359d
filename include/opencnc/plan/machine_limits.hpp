// SPDX-License-Identifier: GPL-3.0-or-later
// Per-axis kinematic limits the planner must never exceed (from the machine profile).
#pragma once

#include <array>

#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::plan {

/// Limits of one axis, in mm (linear) or degrees (rotary) per second, s², s³.
struct AxisLimits {
  double max_velocity = 0;      ///< > 0 for every configured axis
  double max_acceleration = 0;  ///< > 0 for every configured axis
  double max_jerk = 0;          ///< 0 = not limited
};

/// The machine's axes and their limits. Only axes in `axes` may move.
struct MachineLimits {
  AxisMask axes = AxisMask::from_letters("XYZ");
  std::array<AxisLimits, kAxisCount> axis{};

  /// The same limits on every axis of `mask`. Any thread.
  static MachineLimits uniform(AxisMask mask, double velocity, double acceleration, double jerk = 0) {
    MachineLimits m;
    m.axes = mask;
    for (int i = 0; i < kAxisCount; ++i) {
      if (mask.has(static_cast<Axis>(i)))
        m.axis[static_cast<std::size_t>(i)] = {velocity, acceleration, jerk};
    }
    return m;
  }
  const AxisLimits& operator[](int i) const noexcept { return axis[static_cast<std::size_t>(i)]; }
};

/// Adds an error to `diags` (code "plan.limits") for every configured axis whose limits are not
/// positive finite numbers. Returns true when the limits are usable. Any thread; non-real-time.
bool validate(const MachineLimits& limits, Diagnostics& diags);

}  // namespace opencnc::plan
