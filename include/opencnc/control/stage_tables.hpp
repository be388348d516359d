// SPDX-License-Identifier: GPL-3.0-or-later
// The tick's tables an admin's edit of the profile changes while nothing moves (the joints' pitch
// tables, the EDM's machining conditions), staged in the channels for one ApplyJointLimits.
#pragma once

#include <cstdint>
#include <vector>

#include "opencnc/control/channels.hpp"
#include "opencnc/control/command.hpp"
#include "opencnc/control/servo_config.hpp"

namespace opencnc::control {

/// Writes the tables of `next` into the channels where the tick does not read them — each
/// compensated joint's pitch table into the buffer its tick does not read (as the tick publishes
/// it, not as a controller remembers it: the tick may have outlived the controller that switched
/// it), the machining conditions into their table (the tick reads it only in the apply) — and
/// returns the commands that name them, each with `stage_id`, to be sent before the apply. Every
/// table is staged at every change, changed or not: a stage left in the tick by a change whose
/// commands did not all fit in the ring is always overwritten before the next apply, and an
/// unchanged table switches without any take-up. Non-real-time; the controller's thread, nothing
/// else staged meanwhile.
std::vector<Command> stage_tables(ServoChannels& channels, const ServoConfig& next, std::uint64_t stage_id);

}  // namespace opencnc::control
