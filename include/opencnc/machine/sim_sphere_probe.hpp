// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated probe input of an electrode touching a reference sphere (electrode setting).
#pragma once

#include <array>

#include "opencnc/core/vec3.hpp"
#include "opencnc/machine/sim_config.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {

/// The contact between the electrode in the spindle and a reference sphere. The electrode's tip
/// is a ball of radius `tip_radius` whose lowest point is at the spindle's controlled point less
/// the electrode's offsets (the tool table's X, Y, Z: G43 puts the controlled point at program
/// point + offset), so its centre is at p − offset + tip_radius·ẑ. The contact closes when the
/// two balls meet (a fresh uniform jitter in ±noise per sample) and opens `hysteresis` off the
/// surface. Real-time safe.
class SimSphereProbe {
 public:
  constexpr SimSphereProbe() noexcept = default;
  explicit SimSphereProbe(const SimSphereTarget& target) noexcept : target_(target), centre_(target.centre) {}

  bool present() const noexcept { return target_.present; }
  /// The electrode in the spindle: its offsets (X, Y, Z) and tip radius, mm.
  void set_electrode(const Vec3& offset, double tip_radius) noexcept {
    offset_ = offset;
    tip_radius_ = tip_radius;
  }
  const Vec3& offset() const noexcept { return offset_; }
  double tip_radius() const noexcept { return tip_radius_; }
  /// B stands at `b_deg`: a sphere that turns with B has its centre turned about B's true axis
  /// by b_deg − b_at_centre_deg (right-handed about its direction; about +Y, +B turns Z toward X).
  void turn(double b_deg) noexcept;
  /// The sphere's centre now, machine coordinates.
  const Vec3& centre() const noexcept { return centre_; }
  /// The distance between the tip's surface and the sphere's at table positions `p` (X, Y, Z):
  /// negative when they overlap.
  double gap(const Vec3& p) const noexcept;
  /// Samples the contact at `p`; draws one noise value when noise > 0. After a change of state,
  /// edge_fraction() says where between the previous sample and this one it happened.
  bool update(const Vec3& p, SplitMix64& rng) noexcept;
  double edge_fraction() const noexcept { return edge_fraction_; }

 private:
  SimSphereTarget target_{};
  Vec3 centre_{};
  Vec3 offset_{};
  double tip_radius_ = 0;
  bool active_ = false;
  bool sampled_ = false;
  double last_gap_ = 0;
  double edge_fraction_ = 1;
};

}  // namespace opencnc::machine
