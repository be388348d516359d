// SPDX-License-Identifier: GPL-3.0-or-later
// MotionCodes — the motion of one engine's blocks: end points (distance modes, G53, polar),
// straight moves, arcs and helices with their centre rules, inverse-time feeds (motion.cpp).
#pragma once

#include <string_view>

#include "opencnc/core/axes.hpp"

namespace opencnc::canon {
struct ArcFeed;
}

namespace opencnc::gcode {

class Engine;
struct Block;

/// Converts the motion of the engine's block (`motion`: the G code ×10) into canon moves.
/// Reaches the engine's state through `e_` (a friend of the engine). Interpreter thread.
class MotionCodes {
 public:
  explicit MotionCodes(Engine& e) noexcept : e_(e) {}
  MotionCodes(const MotionCodes&) = delete;
  MotionCodes& operator=(const MotionCodes&) = delete;

  /// The block's end point in program coordinates (its axis words, distance mode, G53, polar).
  Pose find_ends(const Block& b);
  /// G0, G1, G2, G3, G80, or an extension's motion code.
  void convert_motion(int motion);
  /// Emits a straight move to `end`, through cutter compensation when it is on.
  void emit_straight(bool rapid, const Pose& end);
  void emit_arc(const canon::ArcFeed& arc);
  /// The centre of an arc given by I/J/K (`off1`, `off2`) or by its radius, in the plane's
  /// first and second axes, and its signed turn count (LinuxCNC's rules and tolerances).
  void arc_center_ijk(int motion, double cur1, double cur2, double end1, double end2, double off1,
                      double off2, int turns, double& c1, double& c2, int& turn) const;
  void arc_center_r(int motion, double cur1, double cur2, double end1, double end2, double radius, int turns,
                    double& c1, double& c2, int& turn) const;
  /// G93: the feed rate that makes the arc last 1/F minutes.
  void inverse_time_arc(double c1, double c2, double c3, double cx, double cy, int turn, double e1, double e2,
                        double e3);

 private:
  [[noreturn]] static void polar_with_xy(const Block& b);
  [[noreturn]] static void polar_at_origin(const Block& b);
  void check_feed(std::string_view what) const;
  void convert_straight(int motion);
  void convert_arc(int motion);
  void inverse_time_straight(const Pose& end);
  void check_habits(bool feed);

  Engine& e_;
  bool warned_units_ = false;    ///< the program moved before any G20/G21 (said once)
  bool warned_spindle_ = false;  ///< it fed with the spindle stopped (said once)
  /// Neither can be said any more (the units programmed or said, the spindle said or absent): the
  /// moves skip the habits' checks (a call on every line otherwise, gcode_bench).
  bool habits_settled_ = false;
};

}  // namespace opencnc::gcode
