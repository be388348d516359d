// SPDX-License-Identifier: GPL-3.0-or-later
// The EDM's reach in the soft-limit check: what the gap servo's orbit and axis jump add around
// the programmed path while a machining condition is in force, and for a while after it.
#pragma once

#include <cstddef>
#include <string>

#include "opencnc/controller/preflight.hpp"

namespace opencnc::edm {

/// What the gap servo may add to a move's extent: an orbit's radius on both orbit axes, an axis
/// jump's height on the tool axis (away from the work), and the condition that gives the larger.
struct Reach {
  double orbit_mm = 0;
  double jump_mm = 0;
  int orbit_condition = 0, jump_condition = 0;  ///< whose orbit and jump (0: none)
};

/// Follows the program's M180 P<n> / M181: while a condition is in force a move's extent is
/// widened by what the gap servo adds to the path: the condition's orbit radius on both orbit axes
/// and an axis jump's height on the tool axis, away from the work. A condition switched off (M181)
/// or replaced by another keeps widening the moves after it while its orbit may still be spiralling
/// back to the centre (its radius at the rate it grew) or a jump coming down: every move that may
/// start within that time — each move's shortest possible time its widest axis' travel at that
/// axis' max_velocity, so the count errs toward more moves. Non-real-time; one thread.
class ReachCheck final : public controller::MoveReach {
 public:
  explicit ReachCheck(const control::ServoConfig& config) : config_(config) {}
  std::string widen(const canon::Program& program, canon::SegmentId move,
                    controller::Extent& extent) override;
  void reset() override { program_ = nullptr; }

 private:
  /// Follows the EDM codes up to move `move` and returns what the gap servo may add to it.
  Reach reach_at(const canon::Program& program, std::size_t move);
  /// The condition `n` leaves widening the moves after it for its spiral back and its jump.
  void start_tail(int n);

  control::ServoConfig config_;
  // The EDM codes seen so far in the program being checked.
  const canon::Program* program_ = nullptr;
  std::size_t next_action_ = 0, last_move_ = 0;
  int on_ = 0;  ///< the condition in force (0: none)
  /// A condition switched off or replaced: what its offsets may still add, and for how long
  /// after its code (seconds, against the shortest time the moves since could have taken).
  Reach tail_{};
  double tail_s_ = 0, since_s_ = 0;
  bool tail_first_ = false;     ///< the first move after the code: widened whatever its time
  std::size_t timed_move_ = 0;  ///< the moves before this one have been added to since_s_
  Reach last_reach_{};          ///< move last_move_'s, for a check of it again
};

}  // namespace opencnc::edm
