// SPDX-License-Identifier: GPL-3.0-or-later
// Whole numbers from program values: LinuxCNC casts doubles to int; here values beyond the
// int range saturate (so they meet the range checks) instead of being undefined behaviour.
#pragma once

#include <climits>

namespace opencnc::gcode {

/// `x` truncated toward zero, saturated to the int range (NaN gives INT_MIN).
inline int trunc_to_int(double x) noexcept {
  if (!(x > -2147483649.0)) return INT_MIN;
  if (!(x < 2147483648.0)) return INT_MAX;
  return static_cast<int>(x);
}

/// `x` rounded half away from zero, saturated to the int range.
inline int round_to_int(double x) noexcept { return trunc_to_int(x < 0.0 ? x - 0.5 : x + 0.5); }

}  // namespace opencnc::gcode
