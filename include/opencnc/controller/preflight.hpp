// SPDX-License-Identifier: GPL-3.0-or-later
// Preflight: the whole program checked against the soft limits before any motion starts.
#pragma once

#include <array>

#include "opencnc/canon/program.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/plan/machine_limits.hpp"

namespace opencnc::control {

/// Axis-aligned extent of a move, every axis, machine coordinates.
struct Extent {
  Pose min{}, max{};
};

/// The extent of move `id` of `program`: the end points of a line; for an arc or helix its true
/// extent (the circle's extreme points in the plane where the sweep passes them). Non-real-time.
Extent move_extent(const canon::Program& program, canon::SegmentId id);

/// The length of move `id` along X Y Z (U V W for moves without XYZ motion): the distance for a
/// line, the helix length for an arc. Non-real-time.
double move_length(const canon::Program& program, canon::SegmentId id);

/// Checks every move of `program` (from its start) against the soft limits of the joints in
/// `config` (wrapped rotary joints have none). Adds one `control.soft-limit` error per move and
/// axis that would cross a limit, with the move's file and line, and returns false if there was
/// any. Non-real-time; O(moves).
bool check_soft_limits(const canon::Program& program, const ServoConfig& config, Diagnostics& diags);

/// What every move passes before it may run: the soft limits of the joints (as
/// check_soft_limits) and the planner's own checks (plan::check_move). The preflight scan uses
/// it on every move of a program, the controller again on every move of a running one (where
/// a real probe result or input value may have changed it). Non-real-time; one thread.
///
/// What the gap servo may add to a move's extent: an orbit's radius on both orbit axes, an axis
/// jump's height on the tool axis (away from the work), and the condition that gives the larger.
struct EdmReach {
  double orbit_mm = 0;
  double jump_mm = 0;
  int orbit_condition = 0, jump_condition = 0;  ///< whose orbit and jump (0: none)
};

/// On an EDM (`config.edm`) it follows the program's M180 P<n> / M181: while a condition is in
/// force a move's extent is widened by what the gap servo adds to the path: the condition's orbit
/// radius on both orbit axes and an axis jump's height on the tool axis, away from the work. A
/// condition switched off (M181) or replaced by another keeps widening the moves after it while
/// its orbit may still be spiralling back to the centre (its radius at the rate it grew) or a jump
/// coming down: every move that may start within that time — each move's shortest possible time
/// its widest axis' travel at that axis' max_velocity, so the count errs toward more moves.
class MachineMoveCheck final : public MoveCheck {
 public:
  MachineMoveCheck(const ServoConfig& config, const plan::MachineLimits& limits) : config_(config), limits_(limits) {}
  bool check(const canon::Program& program, canon::SegmentId move, Diagnostics& diags) override;
  /// Soft-limit crossings after the first few are counted, not listed: adds one line for them
  /// (call after the last check of a scan) and starts counting afresh.
  void finish(Diagnostics& diags) override;

 private:
  /// Follows the EDM codes up to move `move` and returns what the gap servo may add to it.
  EdmReach edm_reach_at(const canon::Program& program, std::size_t move);
  /// The condition `n` leaves widening the moves after it for its spiral back and its jump.
  void start_edm_tail(int n);

  ServoConfig config_;
  plan::MachineLimits limits_;
  int soft_limit_errors_ = 0;
  // The EDM codes seen so far in the program being checked.
  const canon::Program* edm_program_ = nullptr;
  std::size_t edm_next_action_ = 0, edm_last_move_ = 0;
  int edm_on_ = 0;  ///< the condition in force (0: none)
  /// A condition switched off or replaced: what its offsets may still add, and for how long
  /// after its code (seconds, against the shortest time the moves since could have taken).
  EdmReach edm_tail_{};
  double edm_tail_s_ = 0, edm_since_s_ = 0;
  bool edm_tail_first_ = false;     ///< the first move after the code: widened whatever its time
  std::size_t edm_timed_move_ = 0;  ///< the moves before this one have been added to edm_since_s_
  EdmReach edm_last_reach_{};       ///< move edm_last_move_'s, for a check of it again
};

}  // namespace opencnc::control
