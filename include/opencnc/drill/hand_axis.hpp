// SPDX-License-Identifier: GPL-3.0-or-later
// The hand-axis pass: on a machine with hand-fed axes (the drill's quill) every programmed motion
// of such an axis becomes a wait for the operator, as the program's moves are built.
#pragma once

#include <array>

#include "opencnc/canon/program.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/extensions.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::drill {

/// The hand-fed axes of a machine and what the pass checks against.
struct HandAxes {
  AxisMask axes;
  std::array<double, kAxisCount> min_limit{}, max_limit{};
  bool any() const noexcept { return axes.bits() != 0; }
};

/// The manual axes of `profile`. Any thread.
HandAxes hand_axes(const config::MachineProfile& profile);

/// Rewrites the moves of a program as they are appended so that none changes a hand axis: each
/// keeps its number, its hand coordinates become those of the program's start (nothing commands
/// them), and where it moved a hand axis to h a HandAxisWait action stands — the servo waits there
/// until the operator has brought the axis to h (moving in +, a retract: at or above h less the
/// axis' tolerance; moving in −, a plunge: down to h plus the tolerance) and then holds the run
/// while the axis leaves h (control::HandWait). A move that also moves driven axes is split by
/// safety: a retract is waited for before the table moves, a plunge after it. Arcs in a plane of a
/// hand axis, helices, probes and spindle-synchronised moves cannot move one, and a target beyond
/// the axis' soft limits is refused: errors at the move's line (code control.hand-axis) in
/// failures(). Non-real-time; one thread (the program's builder's).
class HandAxisFilter final : public controller::MovePass {
 public:
  explicit HandAxisFilter(const HandAxes& hand) : hand_(hand) {}

  /// Handles the moves of `program` appended since the last call (and the first call after
  /// restart()); waits are appended as actions, so call it right after each move is appended.
  void process(canon::Program& program) override;
  /// The program is a new leg (a new window, its moves numbered from 0 again, starting where the
  /// machine stands).
  void restart() noexcept override { started_ = false; }
  const Diagnostics& failures() const noexcept override { return failures_; }

 private:
  void process_move(canon::Program& program, canon::SegmentId id);
  bool in_plane(canon::Plane plane) const noexcept;
  void fail(const canon::Program& program, canon::SegmentId id, std::string message);

  HandAxes hand_;
  bool started_ = false;
  std::size_t next_ = 0;  ///< first move not handled yet
  Pose fixed_{};          ///< the hand coordinates every move gets (the leg's start)
  Pose programmed_{};     ///< the hand coordinates the program asked for last
  Diagnostics failures_;
};

}  // namespace opencnc::drill
