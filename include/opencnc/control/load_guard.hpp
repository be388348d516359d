// SPDX-License-Identifier: GPL-3.0-or-later
// The load guard's configuration: a process load input and the thresholds that hold or retract.
#pragma once

#include <cstdint>

namespace opencnc::control {

/// What the tick's load guard does with a process load (the broach's cutting force, kN, on an
/// analog input): above `hold` the feed is held on the path (couplings kept); above `retract` the
/// run stops on the path and the radial axis then lifts the cutter by `retract_lift`. A level
/// counts once the input has stayed above it for `confirm_periods` periods in a row (a load cell's
/// noise is not an overload). Plain data, built from `[process.broaching]`.
struct LoadGuardConfig {
  double hold_kn = 0;                ///< feed hold above this (0: no hold level)
  double retract_kn = 0;             ///< stop and retract above this (0: no retract level)
  double retract_lift = -0.5;        ///< signed distance along the radial axis, units
  double retract_speed = 0;          ///< units/s of the lift (0: the axis' maximum velocity)
  std::int32_t input = 0;            ///< analog input channel carrying the load, kN
  std::int32_t confirm_periods = 3;  ///< consecutive periods above a level before it acts
  bool enabled = false;
  std::int8_t radial_axis = 0;  ///< the axis that lifts the cutter (Axis index)
  /// Explicit, zeroed: the shared set-up is compared byte for byte (no implicit padding).
  std::uint8_t reserved[6]{};
};

/// What the guard did last (status and events). Plain data.
enum class LoadAction : std::uint8_t {
  None,
  Hold,     ///< the load passed the hold level: feed hold
  Retract,  ///< the load passed the retract level: stop on the path, then the lift
  Lifted,   ///< the retract's lift is done
};

/// Names for logs and status lines. Any thread; real-time safe.
const char* to_string(LoadAction a) noexcept;

}  // namespace opencnc::control
