// SPDX-License-Identifier: GPL-3.0-or-later
// Calibration on the simulated machine (`opencnc calibrate`): the repeatability of the home
// reference, and a positioning test in the spirit of ISO 230-2 before and after compensation,
// whose measured table can go into the profile.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/core/axes.hpp"

namespace opencnc::drill {

/// What `homing_spread` does.
struct HomingSpreadOptions {
  int runs = 10;
  std::uint64_t seed = 1;
  /// Each run's temperature is drawn uniformly in the profile's ± half this (°C): the shop over a day.
  double temperature_swing_c = 10;
  /// Called with every servo period of the first run (for a trace), if set.
  std::function<void(const control::TraceSample&)> trace;
};

/// Of every axis that homes on a decel_midpoint sensor: the origin each run found (the middle of
/// the two edges) and what its rising edge alone would have given, in the simulated machine's own
/// frame (its motor position: the ground truth, the same in every run).
struct HomingSpread {
  AxisMask axes;
  int runs = 0;
  double temperature_min_c = 0, temperature_max_c = 0;
  std::array<std::vector<double>, kAxisCount> midpoint{}, rising{};
  /// max − min over the runs, mm.
  std::array<double, kAxisCount> midpoint_spread{}, single_edge_spread{};
};

/// `runs` homing cycles, each on a fresh simulated machine (its own noise seed) from a random
/// start position within the soft limits and at a random temperature. Non-real-time; throws
/// std::runtime_error when a run does not home.
HomingSpread homing_spread(const config::MachineProfile& profile, const HomingSpreadOptions& options);

/// What `measure_positioning` does.
struct PositioningOptions {
  AxisMask axes;             ///< axes to measure (driven, homed ones)
  double interval = 50;      ///< targets every this many units from the home position …
  double overrun = 5;        ///< … within the soft limits less this; each is approached from this far
  int approaches = 5;        ///< per target and direction
  double feed = 1500;        ///< units/min of the approaches (G1)
  double dwell_s = 0.25;     ///< settling before each reading
  double resolution = 1e-4;  ///< of the simulated scale (a laser), units
  std::uint64_t seed = 1;    ///< of the simulated machine
};

/// One axis' positioning: per target the mean and standard deviation of the deviations (actual −
/// target, the scale zeroed at the first target approached upward) in each direction, and the
/// ISO 230-2 figures over them: with x̄↑, s↑, x̄↓, s↓ at each target and B = x̄↑ − x̄↓,
///   reversal      = max |B|,
///   repeatability = max over targets of max(2s↑ + 2s↓ + |B|, 4s↑, 4s↓),
///   accuracy      = max(x̄↑ + 2s↑, x̄↓ + 2s↓) − min(x̄↑ − 2s↑, x̄↓ − 2s↓) over every target.
struct AxisPositioning {
  std::vector<double> targets;
  std::vector<double> mean_up, mean_down, sd_up, sd_down;
  double accuracy = 0, repeatability = 0, reversal = 0;  ///< mm
};

struct Positioning {
  AxisMask axes;
  std::array<AxisPositioning, kAxisCount> axis{};
};

/// The positioning test through the whole controller (homing, MDI moves, planner, servo with the
/// profile's compensation, simulated machine), one axis at a time with the others at home: linear
/// cycles up through the targets and back down, `approaches` times; each reading after
/// `dwell_s` at rest, of the table's true position. Non-real-time; throws std::runtime_error when
/// the machine refuses a step (with its reason).
Positioning measure_positioning(const config::MachineProfile& profile, const PositioningOptions& options);

/// The profile without any compensation (what "before" measures).
config::MachineProfile without_compensation(const config::MachineProfile& profile);

/// The compensation a measurement gives: its mean deviations as the tables of each direction (the
/// reversal, hence the backlash, is in them: backlash 0), the take-up limits of `previous` (or
/// the defaults).
config::CompensationProfile compensation_from(const AxisPositioning& measured,
                                              const config::AxisProfile& axis);

}  // namespace opencnc::drill
