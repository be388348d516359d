// SPDX-License-Identifier: GPL-3.0-or-later
// Arc arithmetic shared by the interpreter's arcs and cutter compensation, in LinuxCNC's
// precision (its angles add ±π/2 and 2π in long double and round the sum to double).
#pragma once

#include <cmath>

namespace opencnc::gcode {

inline constexpr long double kPiL = 3.141592653589793238462643383279502884L;

/// LinuxCNC's default tolerance of an arc's end radius against its start radius (absolute).
inline constexpr double kSpiralToleranceInch = 2 * 0.001 * 1.41421356237309504880;
inline constexpr double kSpiralToleranceMm = 2 * 0.01 * 1.41421356237309504880;

/// `angle + offset` computed in long double and rounded, as LinuxCNC does with M_PIl terms.
inline double add_long(double angle, long double offset) noexcept {
  return static_cast<double>(static_cast<long double>(angle) + offset);
}

/// Angle (rad) swept from (x1,y1) to (x2,y2) about (cx,cy) for a signed turn count
/// (G3 > 0, G2 < 0, |turn| - 1 extra full circles); 0 for turn 0.
inline double find_turn(double x1, double y1, double cx, double cy, int turn, double x2, double y2) noexcept {
  if (turn == 0) return 0.0;
  const long double two_pi = 2 * kPiL;
  double alpha = std::atan2(y1 - cy, x1 - cx);
  double beta = std::atan2(y2 - cy, x2 - cx);
  if (turn > 0) {
    if (beta <= alpha) beta = static_cast<double>(beta + two_pi);
    return static_cast<double>((beta - alpha) + (turn - 1) * two_pi);
  }
  if (alpha <= beta) alpha = static_cast<double>(alpha + two_pi);
  return static_cast<double>((beta - alpha) + (turn + 1) * two_pi);
}

}  // namespace opencnc::gcode
