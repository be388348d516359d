// SPDX-License-Identifier: GPL-3.0-or-later
// A canonical program's action as the machine action the tick applies at its marker: every stage's
// action (spindle, coolant, outputs, waits, the hand axes', the coupling's, process codes).
#pragma once

#include <cstdint>
#include <optional>

#include "opencnc/canon/program.hpp"
#include "opencnc/control/command.hpp"
#include "opencnc/control/servo_config.hpp"

namespace opencnc::control {

/// The machine side of action `index` of `program` when the planner turns it into a marker the
/// servo must act on (a Report or Sync marker), else nothing. `servo` (the tick's configuration)
/// names the axes whose origin an action carries (the coupling's master and slave). Non-real-time.
std::optional<MachineAction> machine_action(const canon::Program& program, std::uint32_t index,
                                            const ServoConfig* servo = nullptr);

}  // namespace opencnc::control
