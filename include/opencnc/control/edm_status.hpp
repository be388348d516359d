// SPDX-License-Identifier: GPL-3.0-or-later
// EdmStatus — the EDM gap servo's state in the status snapshot and every trace sample (docs/edm.md).
#pragma once

#include <cstdint>
#include <type_traits>

#include "opencnc/machine/machine_io.hpp"

namespace opencnc::control {

/// The gap servo's state, for status and trace. Plain data.
struct EdmStatus {
  bool on = false;         ///< a condition is selected and the generator programmed on
  bool generator = false;  ///< the generator's pulses are on now (off while lifted or held)
  int condition = 0;       ///< the active condition's number (0: none)
  machine::GapState gap_state = machine::GapState::Open;
  double gap_voltage_v = 0;         ///< as measured this period
  double filtered_voltage_v = 0;    ///< after the servo's low-pass filter
  double path_speed_mm_s = 0;       ///< signed speed along the path (− = backing off)
  double backlog_mm = 0;            ///< how far behind the interpolator's head the electrode stands
  bool retract_limit = false;       ///< backing off reached the end of the path memory
  double short_s = 0;               ///< how long the gap has been shorted while machining
  bool jumping = false;             ///< a jump is lifting or returning
  double jump_lift_mm = 0;          ///< how far the jump has lifted the electrode
  std::uint32_t jumps = 0;          ///< jumps begun since the machine started
  double orbit_radius_mm = 0;       ///< the orbit's radius now
  double orbit_offset[2] = {0, 0};  ///< the orbit's offset in its plane
  bool finishing = false;           ///< the finishing cycle holds the burn at the path's end
  // The servo's and the jump's settings in force (the condition's, or as adaptive control set them).
  double servo_reference_v = 0;
  double gain_mm_s_per_v = 0;
  double jump_period_s = 0;
  double jump_height_mm = 0;
  float abnormal_share = 0;       ///< adaptive control's last window: share of arc and short periods
  float voltage_spread = 0;       ///< … and the gap voltage's standard deviation over the reference
  std::uint32_t adaptations = 0;  ///< windows in which adaptive control changed a setting (since start)
};

static_assert(std::is_trivially_copyable_v<EdmStatus>);

}  // namespace opencnc::control
