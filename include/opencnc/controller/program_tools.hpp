// SPDX-License-Identifier: GPL-3.0-or-later
// What the controller needs to do with a canon::Program besides planning it: restart it from
// another position, and turn its actions into the machine actions the servo applies.
#pragma once

#include <memory>
#include <optional>

#include "opencnc/canon/program.hpp"
#include "opencnc/control/command.hpp"

namespace opencnc::motion {
struct CouplingConfig;
}

namespace opencnc::control {

/// A copy of `program` from move `from` on, whose first move starts at `start`. Its moves are
/// numbered from 0 again (move k is move from + k of the original); the path-control and
/// override settings made before `from` are kept (at its start), other earlier actions are
/// dropped. Used to run a program from where the machine stands (after a probe trip, or when
/// it has moved since the program was loaded). Non-real-time; O(size).
std::shared_ptr<canon::Program> program_tail(const canon::Program& program, canon::SegmentId from,
                                             const Pose& start);

/// The machine side of action `index` of `program` when the planner turns it into a marker the
/// servo must act on (a Report or Sync marker), else nothing. `coupling` (the servo's) names the
/// master and slave whose origin a coupling action carries. Non-real-time.
std::optional<MachineAction> machine_action(const canon::Program& program, std::uint32_t index,
                                            const motion::CouplingConfig* coupling = nullptr);

}  // namespace opencnc::control
