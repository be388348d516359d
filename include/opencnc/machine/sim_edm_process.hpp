// SPDX-License-Identifier: GPL-3.0-or-later
// SimEdmProcess — the simulated spark gap of a sinker EDM: gap distance along the tool axis,
// material removal per discharge, debris, open / normal / arc / short with a noisy voltage.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/machine/edm.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {

/// A 1-D model of the gap (docs/edm.md, "The simulated process"): the work's front is a plane
/// across the tool axis that recedes as discharges remove material; the gap is the electrode's
/// distance to it. Averaged over a servo period: the mean gap voltage of the discharges in it.
/// Deterministic for a seed. Real-time safe; called by SimMachine once per period.
class SimEdmProcess {
 public:
  static constexpr int kMaxFronts = 8;

  void configure(const SimEdmConfig& config, double period_s) noexcept;
  /// One period with the electrode at `electrode` (joint coordinates along the feed joint),
  /// the work's orientation joints at `orientation`, the generator's outputs `gen`.
  void step(double electrode, const double orientation[2], bool generator_on, const GeneratorOutputs& gen,
            SplitMix64& rng) noexcept;
  /// What the sensor reports for the period just simulated.
  void sample(ProcessInputs& in) const noexcept;

  /// Fault injection: a debris bridge shorts the gap from the next period the generator is on
  /// until the electrode has backed off `short_bridge_mm` further than the gap was.
  void inject_short() noexcept { short_pending_ = true; }

  // Ground truth, for tests.
  double gap_mm() const noexcept { return gap_mm_; }
  double debris() const noexcept { return debris_; }
  /// Depth burnt below the surface at the current orientation, mm.
  double depth_mm() const noexcept;
  std::uint64_t discharges() const noexcept { return discharges_; }

 private:
  int front_for(const double orientation[2]) noexcept;
  void discharge(const GeneratorOutputs& gen, double x, SplitMix64& rng) noexcept;

  SimEdmConfig config_{};
  double period_s_ = 1e-3;
  std::array<double, kMaxFronts> front_{};          ///< each orientation's front, joint coordinates
  std::array<std::int32_t, kMaxFronts * 2> key_{};  ///< its orientation in whole degrees
  int fronts_ = 0, front_index_ = 0;
  double gap_mm_ = 0, debris_ = 0;
  double voltage_v_ = 0;
  GapState state_ = GapState::Open;
  bool short_ = false, short_pending_ = false;
  double bridge_until_mm_ = 0;
  std::uint64_t discharges_ = 0;
};

}  // namespace opencnc::machine
