// SPDX-License-Identifier: GPL-3.0-or-later
// A switch of the simulated machine: a position window with hysteresis and seeded noise.
#pragma once

#include <cmath>
#include <cstdint>

#include "opencnc/machine/sim_config.hpp"

namespace opencnc::machine {

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, fast, and the same sequence on every
/// platform, which std:: distributions do not promise. Real-time safe.
class SplitMix64 {
 public:
  constexpr explicit SplitMix64(std::uint64_t seed = 0) noexcept : state_(seed) {}
  constexpr std::uint64_t next() noexcept {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [-1, 1): the top 53 bits as a fraction, doubled and shifted.
  constexpr double symmetric() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-52 - 1.0; }

 private:
  std::uint64_t state_;
};

/// The state of one switch. A switch becomes active when the position enters its window
/// and releases only once the position is `hysteresis` outside it; both switching points
/// move by a fresh uniform sample in ±noise at every evaluation. Real-time safe.
class SimSwitch {
 public:
  constexpr SimSwitch() noexcept = default;
  constexpr SimSwitch(const SwitchWindow& window, double hysteresis, double noise) noexcept
      : window_(window), hysteresis_(hysteresis), noise_(noise) {}

  bool present() const noexcept { return window_.present; }
  bool active() const noexcept { return active_; }

  /// Samples the switch at `position`; draws one noise value when noise > 0.
  bool update(double position, SplitMix64& rng) noexcept {
    if (!window_.present) return false;
    const double jitter = noise_ > 0 ? noise_ * rng.symmetric() : 0.0;
    const double widen = active_ ? hysteresis_ : 0.0;
    const double from = window_.from - widen + jitter, to = window_.to + widen + jitter;
    active_ = position >= from && position <= to;
    // The switching point this evaluation used nearest to the position: where an edge happened.
    edge_ = std::abs(position - from) <= std::abs(position - to) ? from : to;
    return active_;
  }
  /// The switching point of the last update() nearest to its position (with its noise).
  double edge() const noexcept { return edge_; }

 private:
  SwitchWindow window_{};
  double hysteresis_ = 0;
  double noise_ = 0;
  bool active_ = false;
  double edge_ = 0;
};

}  // namespace opencnc::machine
