// SPDX-License-Identifier: GPL-3.0-or-later
// CompPath — cutter compensation's view of one block: the comp plane's coordinates, the tool
// and programmed points, and the queue of moves whose corner is not settled yet.
#pragma once

#include "opencnc/gcode/block.hpp"
#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode::comp {

/// Corners whose direction changes by less than this (rad) are straight; LinuxCNC's value.
inline constexpr double kCornerTolerance = 0.05;

/// A point of the comp plane: (first, second) = (x, y) in G17, (z, x) in G18.
struct PlanePoint {
  double first = 0, second = 0;
};

/// True when the tool runs inside an arc of signed turn `turn` (G3 > 0) on `left`.
constexpr bool tool_inside_arc(bool left, int turn) noexcept {
  return (left && turn > 0) || (!left && turn < 0);
}

/// Wraps the ExecContext for one compensated block. Coordinates are in the comp plane
/// (first, second, normal); everything it keeps between blocks lives in InterpState::comp,
/// the modal state and PositionState::programmed, so the stage object itself stays stateless.
/// Interpreter thread only.
class CompPath {
 public:
  explicit CompPath(ExecContext& ctx);

  bool left() const noexcept { return left_; }
  double radius() const noexcept { return radius_; }
  /// Where the tool is (its centre) and where the program is, (first, second, normal).
  void current(double& c1, double& c2, double& c3) const noexcept;
  void programmed(double& p1, double& p2, double& p3) const noexcept;
  /// Splits a pose into plane coordinates.
  void split(const Pose& p, double& p1, double& p2, double& p3) const noexcept;
  /// Sets the plane coordinates of `p`.
  void place(Pose& p, double p1, double p2, double p3) const noexcept;
  /// The tool is now at (e1, e2, e3) with the other axes of `end`.
  void moved_to(double e1, double e2, double e3, const Pose& end) noexcept;
  /// The programmed point is now (p1, p2, p3).
  void set_programmed(double p1, double p2, double p3) noexcept;
  /// The entry move is made; the next moves are corners.
  void first_move_done() noexcept { st_.modal.comp_first_move = false; }

  /// The first held move, or nullptr when nothing is held.
  const CompQueuedMove* held_front() const noexcept;
  /// The move the corner rules join to: the first held one or, when a stop has released
  /// them, the first of the last queue (LinuxCNC reads its queue's first slot unchecked).
  const CompQueuedMove& front() const noexcept;

  /// Holds a straight move to (e1, e2, e3) whose programmed direction is (dir1, dir2).
  void queue_line(bool rapid, double dir1, double dir2, double e1, double e2, double e3, const Pose& others);
  /// Holds an arc; `sweep` is the programmed sweep (0 for an arc that rounds a corner).
  void queue_arc(double sweep, double e1, double e2, double c1, double c2, int turn, double e3,
                 const Pose& others);
  /// Releases every held move as it stands (LinuxCNC's dequeue).
  void release();
  /// The held moves start at `p` (their gouge checks measure from here).
  void set_start(double p1, double p2) noexcept;
  /// Settles the corner: every held move now ends at `p`; a move that would have to run
  /// backwards (or an arc that would sweep further than programmed) is a gouge. Then releases
  /// them and starts the next moves at `p`. Nothing held: nothing happens.
  void settle(double p1, double p2);

 private:
  // Where the lathe tool's origin is relative to the centre of its nose radius (G18 only).
  void lathe_shift(double& s1, double& s2) const noexcept;
  Pose pose(double e1, double e2, double e3, const Pose& others) const noexcept;

  ExecContext& ctx_;
  InterpState& st_;
  canon::Plane plane_;
  int a1_, a2_, a3_;
  bool left_;
  double radius_;
};

// The four conversions (LinuxCNC's convert_straight_comp1/2 and convert_arc_comp1/2).
void straight_first(CompPath& path, bool rapid, const Pose& end);
void straight_next(CompPath& path, bool rapid, const Pose& end);
void arc_first(CompPath& path, ExecContext& ctx, const Block& block, int motion, const Pose& end);
void arc_next(CompPath& path, ExecContext& ctx, const Block& block, int motion, const Pose& end);

}  // namespace opencnc::gcode::comp
