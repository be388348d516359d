// SPDX-License-Identifier: GPL-3.0-or-later
// OffsetTrack — the offsets the interpreter applied to each move of a job, from the program's
// offset actions, so that the status can say which ones hold at the commanded position.
#pragma once

#include <cstddef>
#include <deque>
#include <utility>

#include "opencnc/canon/program.hpp"
#include "opencnc/controller/controller_status.hpp"

namespace opencnc::controller::detail {

/// Offset changes of a job's stream, keyed by the move they come before. Controller thread.
class OffsetTrack {
 public:
  explicit OffsetTrack(const WorkOffsets& initial = {}) : base_(initial), latest_(initial) {}

  /// Takes the offset actions appended to `p` since the last call (call before the actions are
  /// released).
  void scan(const canon::Program& p);
  /// The offsets in effect for move `move` of the current leg (the changes before it applied).
  /// Moves asked for must not go backward within a leg: the changes passed are folded in.
  const WorkOffsets& at(std::size_t move);
  /// A new leg whose move 0 is move `from` of the current one: the changes before `from` hold,
  /// the later ones are dropped (they are read again), actions are counted from 0 again.
  void restart(std::size_t from);
  /// The offsets after every change read so far.
  const WorkOffsets& latest() const noexcept { return latest_; }

 private:
  WorkOffsets base_;    ///< in effect for the moves before changes_.front()
  WorkOffsets latest_;  ///< after the last change read
  std::deque<std::pair<std::size_t, WorkOffsets>> changes_;  ///< (before_move, offsets from it on)
  std::size_t next_action_ = 0;
};

}  // namespace opencnc::controller::detail
