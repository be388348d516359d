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

/// The same when the generator can only begin to brake `coast` seconds after the piece (the
/// jerk-limited average forbids turning its acceleration round sooner) and keeps at most its
/// speed meanwhile, over path whose budget is at most `A_coast`:
/// v_end² + 2A·Δs + 2·A_coast·v_end·coast ≤ K. Any thread; real-time safe.
inline double end_speed_limit(double K, double v, double A, double tau, double coast,
                              double A_coast) noexcept {
  if (coast <= 0) return end_speed_limit(K, v, A, tau);
  const double b = A * tau + 2.0 * A_coast * coast;
  const double disc = b * b + 4.0 * (K - A * tau * v);
  if (disc < 0) return -1.0;
  return 0.5 * (std::sqrt(disc) - b);
}

}  // namespace opencnc::traj::detail
