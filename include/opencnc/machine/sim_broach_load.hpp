// SPDX-License-Identifier: GPL-3.0-or-later
// The broaching load of the simulated machine: the force on the cutter from the chip it cuts.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "opencnc/machine/sim_config.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {

/// The load model: the workpiece's material as a map over (stroke position, workpiece angle) of
/// the depth cut so far; the chip the cutter meets is how far it stands beyond that depth where it
/// enters a cell. Load = k_c · width · chip · dull · (1 + gain · speed), while the stroke moves.
/// Fixed size, no allocation: every method is real-time safe.
class SimBroachLoad {
 public:
  static constexpr int kStrokeCells = 256;
  static constexpr int kAngleCells = 72;  ///< 5° each

  SimBroachLoad() = default;
  explicit SimBroachLoad(const SimBroachConfig& config, std::uint64_t seed) noexcept;

  /// One period: the cutter at `stroke` moving at `stroke_velocity` (mm/s), the workpiece at
  /// `angle_deg`, the cutter at `radial`. Servo thread.
  void update(double stroke, double stroke_velocity, double angle_deg, double radial) noexcept;
  /// The load cell's reading, kN (noise included).
  double load_kn() const noexcept { return reading_kn_; }
  /// The force on the cutter without noise, N (signed against the stroke's motion).
  double stroke_force_n() const noexcept { return force_n_; }
  /// The chip the cutter meets now, mm.
  double chip_mm() const noexcept { return chip_mm_; }
  void set_dull_factor(double factor) noexcept { dull_ = factor; }
  double dull_factor() const noexcept { return dull_; }
  /// The depth cut so far at a point of the bore, mm beyond the surface.
  double cut_depth(double stroke, double angle_deg) const noexcept;
  /// The workpiece's bore: the depth cut so far in every cell (stroke-major, kStrokeCells ×
  /// kAngleCells), so that a simulation restarted after a power failure can carry it over as a
  /// real workpiece keeps its cut. Any thread that owns the model (between periods).
  std::span<const float> bore() const noexcept { return cut_; }
  /// Takes over a bore (`bore()` of the same geometry); false and nothing changed if its size is
  /// not kStrokeCells × kAngleCells. The cutter is then taken as entering its cell afresh.
  bool restore_bore(std::span<const float> bore) noexcept;

 private:
  int stroke_cell(double stroke) const noexcept;
  static int angle_cell(double angle_deg) noexcept;
  void enter_cell(int cell, double angle_deg, double depth) noexcept;

  SimBroachConfig config_{};
  SplitMix64 rng_{1};
  std::array<float, kStrokeCells * kAngleCells> cut_{};  ///< depth cut so far, mm
  int cell_ = -1;       ///< the stroke cell the cutter is in (−1: outside the bore)
  int direction_ = 0;   ///< the stroke's direction when it entered the cell
  double chip_mm_ = 0;  ///< the chip met on entering the cell
  double dull_ = 1;
  double force_n_ = 0;
  double reading_kn_ = 0;
};

}  // namespace opencnc::machine
