// SPDX-License-Identifier: GPL-3.0-or-later
// The rest of a program from one of its moves, started from another position (a probe trip, a
// program loaded before the machine moved).
#pragma once

#include <memory>

#include "opencnc/canon/program.hpp"

namespace opencnc::canon {

/// A copy of `program` from move `from` on, whose first move starts at `start`. Its moves are
/// numbered from 0 again (move k is move from + k of the original); the path-control and
/// override settings made before `from` are kept (at its start), other earlier actions are
/// dropped. Used to run a program from where the machine stands (after a probe trip, or when
/// it has moved since the program was loaded). Non-real-time; O(size).
std::shared_ptr<Program> program_tail(const Program& program, SegmentId from, const Pose& start);

}  // namespace opencnc::canon
