// SPDX-License-Identifier: GPL-3.0-or-later
// SimPlasmaProcess — the simulated plasma cut: a warped plate, the arc voltage from the torch's
// height and speed, kerfs already cut (the voltage jumps over them), noise, arc-OK after a delay,
// arc losses (random or injected), the float switch or ohmic contact; or, for an oxy-fuel torch,
// the same plate cut by the flame's cutting oxygen and read by a capacitive height sensor (noise,
// higher over a kerf, out of range off the plate) (docs/cutting.md).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/plasma.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {

/// The plate's top as a smooth deterministic surface: plate_z_mm + warp_mm · (the mean of three
/// plane waves of wavelengths λ, 1.7 λ and 2.9 λ, their directions and phases from the seed), so
/// within ±warp_mm of plate_z_mm. Any thread; real-time safe once built.
class PlateSurface {
 public:
  PlateSurface() = default;
  explicit PlateSurface(const SimPlasmaConfig& config) noexcept;
  double z(double x, double y) const noexcept;

 private:
  double mean_ = 0, amplitude_ = 0;
  std::array<double, 3> kx_{}, ky_{}, phase_{};
};

/// One plate and one torch. configure() allocates the kerf map (not real-time); step() and
/// sample() are real-time safe and called by SimMachine once per period. Deterministic for a seed.
class SimPlasmaProcess {
 public:
  void configure(const SimPlasmaConfig& config, double period_s);
  /// One period with the torch's tip at (x, y, z) (the joints' positions), the torch output and
  /// (oxy-fuel) the cutting oxygen output.
  void step(double x, double y, double z, bool torch_on, bool cut_oxygen = false) noexcept;
  /// Plasma: arc-OK, the arc voltage (its analog input) and the plate sensor (its digital input).
  /// Oxy-fuel: the capacitive height sensor (its analog input).
  void sample(MachineInputs& in) noexcept;
  /// Oxy-fuel: the height the sensor reads now before its noise (mm; its range off the plate).
  double sensed_height_mm() const noexcept;
  /// The arc goes out now and stays out until the torch is switched off and on again.
  void inject_arc_loss() noexcept { loss_pending_ = true; }

  // Ground truth, for tests and reports.
  const PlateSurface& surface() const noexcept { return surface_; }
  double height_mm() const noexcept { return height_; }
  bool arc() const noexcept { return arc_; }
  double voltage_v() const noexcept { return voltage_; }
  bool over_kerf() const noexcept { return over_kerf_; }
  std::uint32_t arc_losses() const noexcept { return losses_; }
  /// A kerf has been cut through (x, y).
  bool kerf_at(double x, double y) const noexcept;

 private:
  struct Point {
    double x = 0, y = 0;
  };
  bool cell(double x, double y, std::size_t& index) const noexcept;
  void mark(const Point& p) noexcept;
  void flush_trail() noexcept;
  void lose_arc() noexcept;

  SimPlasmaConfig config_{};
  PlateSurface surface_;
  double period_s_ = 1e-3;
  SplitMix64 rng_{1};
  double cell_mm_ = 0.5;
  long columns_ = 0, rows_ = 0;
  std::vector<std::uint64_t> kerf_;  ///< a bit per cell: cut through
  /// Where the torch has been and the kerf is not marked yet (it is marked once the torch is a
  /// kerf's width away, so the torch never sees its own kerf).
  static constexpr int kTrail = 512;
  std::array<Point, kTrail> trail_{};
  int trail_first_ = 0, trail_count_ = 0;
  Point last_{};
  bool moved_once_ = false;
  double height_ = 0, speed_ = 0, voltage_ = 0;
  bool arc_ = false, blocked_ = false, loss_pending_ = false, over_kerf_ = false;
  bool torch_on_ = false;
  bool on_plate_ = false;  ///< the torch is over the plate's extent
  double transfer_s_ = 0;
  double z_ = 0, plate_ = 0;
  std::uint32_t losses_ = 0;
};

}  // namespace opencnc::machine
