// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated electrode against a reference sphere: the gap between two balls, and where
// between two samples the contact changed.
#include "opencnc/machine/sim_sphere_probe.hpp"

#include <algorithm>
#include <cmath>

#include "opencnc/machine/rotary_axis.hpp"

namespace opencnc::machine {

void SimSphereProbe::turn(double b_deg) noexcept {
  if (target_.b_joint < 0) return;
  constexpr double kRad = 3.14159265358979323846 / 180;
  const Vec3 on_axis{target_.b_axis[0], target_.centre[1], target_.b_axis[1]};
  centre_ =
      rotate_about(target_.centre, on_axis, target_.b_direction, (b_deg - target_.b_at_centre_deg) * kRad);
}

double SimSphereProbe::gap(const Vec3& p) const noexcept {
  const double dx = p[0] - offset_[0] - centre_[0];
  const double dy = p[1] - offset_[1] - centre_[1];
  const double dz = p[2] - offset_[2] + tip_radius_ - centre_[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz) - target_.radius - tip_radius_;
}

bool SimSphereProbe::update(const Vec3& p, SplitMix64& rng) noexcept {
  if (!target_.present) return false;
  const double g = gap(p);
  const double jitter = target_.noise > 0 ? target_.noise * rng.symmetric() : 0.0;
  const double threshold = jitter + (active_ ? target_.hysteresis : 0.0);
  const bool now = g <= threshold;
  if (now != active_) {
    // The gap changes smoothly between two samples: the edge is where it crossed the threshold.
    const double before = sampled_ ? last_gap_ : g;
    edge_fraction_ = before != g ? std::clamp((before - threshold) / (before - g), 0.0, 1.0) : 1.0;
  }
  active_ = now;
  sampled_ = true;
  last_gap_ = g;
  return active_;
}

}  // namespace opencnc::machine
