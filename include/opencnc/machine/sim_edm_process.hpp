// SPDX-License-Identifier: GPL-3.0-or-later
// SimEdmProcess — the simulated spark gap of a sinker EDM: gap distance along the tool axis,
// material removal per discharge, debris, open / normal / arc / short with a noisy voltage, the
// cavity's side walls burnt out to the side gap, the electrode's wear.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/machine/edm.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {

/// Where the electrode and the work stand in a period (joint coordinates).
struct SimEdmPose {
  double feed = 0;                 ///< the feed joint (the tool axis): the electrode's nominal tip
  double lateral[2] = {0, 0};      ///< the joints across the tool axis (the orbit's plane)
  double orientation[2] = {0, 0};  ///< the work's orientation joints (B, C)
};

/// The gap (docs/edm.md, "The simulated spark gap"): the work's front is a plane across the tool
/// axis that recedes as discharges remove material; the gap is the electrode's distance to it.
/// Averaged over a servo period: the mean gap voltage of the discharges in it. Across the tool
/// axis, the cavity's side walls (in kSides directions) are burnt out to the side gap beyond the
/// electrode's outline wherever it goes inside the cavity: the orbit widens the cavity. The
/// electrode loses length by the condition's wear ratio, so the depth needs more feed. With
/// `side_walls = Removal` the walls burn by the side discharges instead: the period's discharges
/// go to the narrowest of the front and the walls (relative to each one's breakdown distance), a
/// wall recedes by their volume over its area, and the gap voltage is that site's.
/// Deterministic for a seed. Real-time safe; called by SimMachine once per period.
class SimEdmProcess {
 public:
  static constexpr int kMaxFronts = 8;
  /// Directions across the tool axis in which the side walls are kept (every 11.25°).
  static constexpr int kSides = 32;
  /// Electrodes whose wear is remembered (by tool number); more share the last slot.
  static constexpr int kMaxElectrodes = 32;

  void configure(const SimEdmConfig& config, double period_s) noexcept;
  /// One period with the electrode and the work at `pose`, the generator's outputs `gen`.
  void step(const SimEdmPose& pose, bool generator_on, const GeneratorOutputs& gen, SplitMix64& rng) noexcept;
  /// Electrode `tool` is put in (a tool change): its wear is its own, kept from earlier use.
  void mount(std::int32_t tool) noexcept;
  /// A new electrode for `tool` (the worn one replaced): its wear starts again from nothing.
  void replace(std::int32_t tool) noexcept;
  /// What the sensor reports for the period just simulated.
  void sample(ProcessInputs& in) const noexcept;

  /// Fault injection: a debris bridge shorts the gap from the next period the generator is on
  /// until the electrode has backed off `short_bridge_mm` further than the gap was.
  void inject_short() noexcept { short_pending_ = true; }

  // Ground truth, for tests.
  double gap_mm() const noexcept { return gap_mm_; }
  double debris() const noexcept { return debris_; }
  /// Depth burnt below the surface at the current orientation (0: none burnt there), and the
  /// deepest of any orientation's, mm.
  double depth_mm() const noexcept;
  double depth_max_mm() const noexcept;
  std::uint64_t discharges() const noexcept { return discharges_; }
  /// Length the mounted electrode has lost, mm; and the most any electrode has lost.
  double electrode_wear_mm() const noexcept { return wear_[static_cast<std::size_t>(electrode_)]; }
  double electrode_wear_max_mm() const noexcept;
  /// The cavity's side wall at the current orientation in direction k (angle k·360°/kSides from
  /// the first lateral joint's +), beyond the electrode's outline where its burn began, mm.
  double side_wall_mm(int k) const noexcept;
  /// The cavity's oversize per side (the walls' mean over the directions) at the current
  /// orientation, and the largest of any orientation's; 0 before a burn.
  double cavity_oversize_mm() const noexcept;
  double cavity_oversize_max_mm() const noexcept;
  /// Where the cavity at the current orientation was begun across the tool axis: the true
  /// electrode tip's lateral joint `i` (0, 1) at its first discharge, mm (0 before a burn).
  double cavity_centre_mm(int i) const noexcept {
    return front_index_ < 0 || i < 0 || i > 1 ? 0.0 : centre_[static_cast<std::size_t>(2 * front_index_ + i)];
  }
  /// The fronts burnt so far (one per orientation), and front f's depth and wall in direction k.
  int fronts() const noexcept { return fronts_; }
  double front_depth_mm(int front) const noexcept {
    return front < 0 || front >= fronts_
               ? 0.0
               : (front_[static_cast<std::size_t>(front)] - config_.surface_mm) * config_.work_direction;
  }
  double wall_mm(int front, int k) const noexcept {
    return front < 0 || front >= fronts_ || k < 0 || k >= kSides
               ? 0.0
               : wall_[static_cast<std::size_t>(front * kSides + k)];
  }
  /// The side gap of the condition burning now (or last), mm.
  double side_gap_mm() const noexcept { return side_gap_mm_; }

 private:
  int front_for(const double orientation[2], bool create) noexcept;
  void select(const GeneratorOutputs& gen) noexcept;
  void burn_sides(const SimEdmPose& pose, double tip) noexcept;
  void lateral_offset(const SimEdmPose& pose, double d[2]) const noexcept;
  int narrowest_side(double tip, double& x) const noexcept;
  void edge_walls(double gap) noexcept;
  void debris_bridge(double breakdown, SplitMix64& rng) noexcept;
  double oversize_of(int front) const noexcept;
  void discharge(const GeneratorOutputs& gen, double x, int side, SplitMix64& rng) noexcept;

  SimEdmConfig config_{};
  double period_s_ = 1e-3;
  std::array<double, kMaxFronts> front_{};          ///< each orientation's front, joint coordinates
  std::array<std::int32_t, kMaxFronts * 2> key_{};  ///< its orientation in whole degrees
  int fronts_ = 0, front_index_ = -1;               ///< −1: no front at the current orientation
  double gap_mm_ = 0, debris_ = 0;
  double voltage_v_ = 0;
  GapState state_ = GapState::Open;
  bool short_ = false, short_pending_ = false;
  double bridge_until_mm_ = 0;
  std::uint64_t discharges_ = 0;
  // The side walls: each front's centre (lateral joints where its burn began) and walls.
  std::array<bool, kMaxFronts> burning_{};
  std::array<double, kMaxFronts * 2> centre_{};
  std::array<double, kMaxFronts * kSides> wall_{};
  std::array<double, kSides * 2> direction_{};  ///< unit vectors (cos, sin) of the directions
  // The condition burning: its side gap and wear ratio.
  std::int32_t condition_ = -1;
  double side_gap_mm_ = 0, wear_ratio_ = 0;
  /// With a removal rate of the walls: the side's breakdown distance (clean dielectric), the side
  /// gap over the share of it at which the mean voltage is the table's reference.
  double side_breakdown_mm_ = 0;
  double side_reach_[2] = {0, 0};  ///< the electrode's lateral offset from the burn's centre this period
  // The electrodes: tool numbers and each one's lost length.
  std::array<std::int32_t, kMaxElectrodes> tool_{};
  std::array<double, kMaxElectrodes> wear_{};
  int electrodes_ = 1, electrode_ = 0;
};

}  // namespace opencnc::machine
