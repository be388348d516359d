// SPDX-License-Identifier: GPL-3.0-or-later
// A switch of the simulated machine: a position window with hysteresis and seeded noise.
#pragma once

#include <algorithm>
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
    // A window that repeats: the turn whose copy of the window is nearest to the position.
    const double turn =
        window_.period > 0
            ? window_.period * std::round((position - 0.5 * (window_.from + window_.to)) / window_.period)
            : 0.0;
    const double from = window_.from + turn - widen + jitter, to = window_.to + turn + widen + jitter;
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

/// An analog proximity sensor over a window (ProximitySensor): its noisy level and the
/// comparator that makes the digital output of it. Real-time safe.
class SimProximity {
 public:
  constexpr SimProximity() noexcept = default;
  constexpr SimProximity(const SwitchWindow& window, const ProximitySensor& sensor) noexcept
      : window_(window), sensor_(sensor) {}

  bool present() const noexcept { return window_.present; }
  bool active() const noexcept { return active_; }
  double level() const noexcept { return level_; }

  /// The level without noise at `position` with the edges shifted outward by `shift` units.
  double ideal_level(double position, double shift) const noexcept {
    const double rise = (position - (window_.from - shift)) / sensor_.ramp;
    const double fall = ((window_.to + shift) - position) / sensor_.ramp;
    return std::clamp(sensor_.threshold + std::min(rise, fall), 0.0, 1.0);
  }

  /// Samples the sensor at `position` at `temperature_c`; draws one noise value when noise > 0.
  bool update(double position, double temperature_c, SplitMix64& rng) noexcept {
    if (!window_.present) return false;
    const double shift = sensor_.drift_per_k * (temperature_c - kReferenceTemperatureC);
    const double jitter = sensor_.noise > 0 ? sensor_.noise * rng.symmetric() : 0.0;
    level_ = ideal_level(position, shift) + jitter;
    active_ = level_ >= (active_ ? sensor_.threshold - sensor_.hysteresis : sensor_.threshold);
    return active_;
  }

 private:
  SwitchWindow window_{};
  ProximitySensor sensor_{};
  double level_ = 0;
  bool active_ = false;
};

}  // namespace opencnc::machine
