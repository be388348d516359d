// SPDX-License-Identifier: GPL-3.0-or-later
// Preflight: the whole program checked against the soft limits before any motion starts.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/canon/program.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/plan/machine_limits.hpp"

namespace opencnc::controller {

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
bool check_soft_limits(const canon::Program& program, const control::ServoConfig& config, Diagnostics& diags);

/// What a machine's process adds around a programmed move while it runs (an EDM's orbit and axis
/// jump), for the soft-limit check of every move: an extension point of the check (a feature adds
/// one, Controller::add_move_reach). The moves of a scan are checked in order; one of another
/// program, or before the last one, starts afresh. Non-real-time; one thread.
class MoveReach {
 public:
  virtual ~MoveReach() = default;
  /// Widens `extent` (move `move` of `program`) by what the process may add to it and returns the
  /// words a soft-limit error then begins with ("with EDM condition 2's orbit (0.08 mm) "); "" when
  /// it adds nothing.
  virtual std::string widen(const canon::Program& program, canon::SegmentId move, Extent& extent) = 0;
  /// The scan is over: the next check starts from its program's start.
  virtual void reset() {}
};

/// Makes a feature's MoveReach for the servo configuration in force (again after a profile edit;
/// null: nothing on this machine).
using MoveReachFactory = std::function<std::unique_ptr<MoveReach>(const control::ServoConfig&)>;

/// What every move passes before it may run: the planner's own checks (plan::check_move) and the
/// soft limits of the joints (as check_soft_limits) by the move's extent widened by what the
/// features' processes add around it (`reaches`). The preflight scan uses it on every move of a
/// program, the controller again on every move of a running one (where a real probe result or
/// input value may have changed it). Non-real-time; one thread.
class MachineMoveCheck final : public MoveCheck {
 public:
  MachineMoveCheck(const control::ServoConfig& config, const plan::MachineLimits& limits,
                   std::vector<std::unique_ptr<MoveReach>> reaches = {});
  bool check(const canon::Program& program, canon::SegmentId move, Diagnostics& diags) override;
  /// Soft-limit crossings after the first few are counted, not listed: adds one line for them
  /// (call after the last check of a scan) and starts counting afresh.
  void finish(Diagnostics& diags) override;

 private:
  control::ServoConfig config_;
  plan::MachineLimits limits_;
  std::vector<std::unique_ptr<MoveReach>> reaches_;
  int soft_limit_errors_ = 0;
};

}  // namespace opencnc::controller
