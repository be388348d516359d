// SPDX-License-Identifier: GPL-3.0-or-later
// SimulationEvent — a control of the simulated machine the HMI's admin may use (docs/api.md,
// "Simulation"): the mains cut and restored, an electrode put in the spindle.
#pragma once

#include <array>
#include <string>

#include "opencnc/core/vec3.hpp"

namespace opencnc::hmi {

struct SimulationEvent {
  /// "mains-off", "mains-on", "electrode" (the simulated electrode's true offsets and tip),
  /// "spindle-load" (a cut's torque on the spindle).
  std::string event;
  Vec3 offset_mm{};                   ///< electrode: X, Y, Z as a tool table holds them
  double tip_radius_mm = 0;           ///< electrode: its tip's ball
  double torque_nm = 0;               ///< spindle-load: N·m against the rotation (0 = none)
};

}  // namespace opencnc::hmi
