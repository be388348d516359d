// SPDX-License-Identifier: GPL-3.0-or-later
// EdmAdaptive: the gap's state over a window, and the rule that moves a condition's settings.
#include "opencnc/control/edm_adaptive.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::control {

namespace {

/// Abnormal periods (arcs, shorts) above this share: the gap is unstable, debris stays in it.
constexpr double kUnstable = 0.04;
/// … at most this share: the gap is clean.
constexpr double kClean = 0.005;
/// The window's mean this far from the reference (share of it): the servo follows too slowly.
constexpr double kLagging = 0.05;
/// The voltage's spread above this share of the reference (with the mean near it): the servo
/// hunts around the reference.
constexpr double kHunting = 0.08;
/// … the mean this close to the reference: the spread is the servo's own, not a transient's.
constexpr double kCentred = 0.02;

/// `x` scaled by `f` within [lo, hi]; lo = hi (or an empty range) keeps it.
double scaled(double x, double f, double lo, double hi) noexcept {
  return hi > lo ? std::clamp(x * f, lo, hi) : x;
}

double shifted(double x, double d, double lo, double hi) noexcept {
  return hi > lo ? std::clamp(x + d, lo, hi) : x;
}

}  // namespace

void EdmAdaptive::reset() noexcept {
  n_ = arcs_ = shorts_ = 0;
  sum_ = sum2_ = 0;
  abnormal_ = spread_ = 0;
}

// The rule, once per window (the makers' adaptive control in spirit: flush more and widen the gap
// when it turns unstable, machine longer between jumps and closer when it is clean):
// - unstable (arcs and shorts above 4 % of the periods): the jump comes sooner (period × 0.8) and
//   lifts higher (× 1.2), the reference rises by 1 V (a wider gap);
// - clean (below 0.5 %): the jump comes later (× 1.05) and lifts less (× 0.97), the reference
//   falls by 0.25 V (a closer gap removes faster);
// - the gain rises (× 1.25) while the window's mean stays more than 5 % off the reference (the
//   servo lags) and falls (× 0.9) when the spread is above 8 % with the mean within 2 % (it hunts).
bool EdmAdaptive::sample(machine::GapState state, double voltage_v, const machine::EdmCondition& base,
                         machine::EdmCondition& active) noexcept {
  ++n_;
  arcs_ += state == machine::GapState::Arc ? 1 : 0;
  shorts_ += state == machine::GapState::Short ? 1 : 0;
  sum_ += voltage_v;
  sum2_ += voltage_v * voltage_v;
  if (n_ < kWindow) return false;
  const double n = n_;
  const double mean = sum_ / n;
  const double ref = active.servo_reference_v > 0 ? active.servo_reference_v : 1.0;
  abnormal_ = static_cast<double>(arcs_ + shorts_) / n;
  spread_ = std::sqrt(std::max(0.0, sum2_ / n - mean * mean)) / ref;
  const machine::EdmCondition before = active;
  if (abnormal_ > kUnstable) {
    active.jump_period_s = scaled(active.jump_period_s, 0.8, base.jump_period_min_s, base.jump_period_max_s);
    active.jump_height_mm =
        scaled(active.jump_height_mm, 1.2, base.jump_height_min_mm, base.jump_height_max_mm);
    active.servo_reference_v =
        shifted(active.servo_reference_v, 1.0, base.servo_reference_min_v, base.servo_reference_max_v);
  } else if (abnormal_ <= kClean) {
    active.jump_period_s = scaled(active.jump_period_s, 1.05, base.jump_period_min_s, base.jump_period_max_s);
    active.jump_height_mm =
        scaled(active.jump_height_mm, 0.97, base.jump_height_min_mm, base.jump_height_max_mm);
    active.servo_reference_v =
        shifted(active.servo_reference_v, -0.25, base.servo_reference_min_v, base.servo_reference_max_v);
  }
  if (std::fabs(mean - ref) > kLagging * ref)
    active.gain_mm_s_per_v =
        scaled(active.gain_mm_s_per_v, 1.25, base.gain_min_mm_s_per_v, base.gain_max_mm_s_per_v);
  else if (spread_ > kHunting && std::fabs(mean - ref) < kCentred * ref)
    active.gain_mm_s_per_v =
        scaled(active.gain_mm_s_per_v, 0.9, base.gain_min_mm_s_per_v, base.gain_max_mm_s_per_v);
  n_ = arcs_ = shorts_ = 0;
  sum_ = sum2_ = 0;
  return active.jump_period_s != before.jump_period_s || active.jump_height_mm != before.jump_height_mm ||
         active.servo_reference_v != before.servo_reference_v ||
         active.gain_mm_s_per_v != before.gain_mm_s_per_v;
}

}  // namespace opencnc::control
