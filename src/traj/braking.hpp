// SPDX-License-Identifier: GPL-3.0-or-later
// The braking law of the tick's one-dimensional generators (the path's and the rigid tap's).
#pragma once

#include <cmath>

namespace opencnc::traj::detail {

/// Largest speed at the end of a constant-acceleration piece of duration tau, starting at speed
/// v, such that the braking curve is respected: v_end² + 2A·Δs ≤ K with Δs = (v + v_end)·tau/2,
/// where K = v_q² + C(q) − C(s) for a limit v_q at q. Negative when no v_end ≥ 0 satisfies it
/// (q is reached within the piece). Any thread; real-time safe.
inline double end_speed_limit(double K, double v, double A, double tau) noexcept {
  const double at = A * tau;
  const double disc = at * at + 4.0 * (K - at * v);
  if (disc < 0) return -1.0;
  return 0.5 * (std::sqrt(disc) - at);
}

}  // namespace opencnc::traj::detail
