// SPDX-License-Identifier: GPL-3.0-or-later
// Value types of the canonical machining interface (between interpreter and everything else).
#pragma once

#include <cstdint>
#include <limits>

#include "opencnc/core/axes.hpp"

namespace opencnc::canon {

/// Ordinal of a motion in execution order (0 = the first motion of the program).
using SegmentId = std::uint64_t;
inline constexpr SegmentId kNoSegment = std::numeric_limits<SegmentId>::max();

enum class Units : std::uint8_t { Mm, Inch };
constexpr double mm_per_unit(Units u) noexcept { return u == Units::Inch ? 25.4 : 1.0; }

/// Canonical planes. XY/YZ/XZ are G17/G19/G18; UV/VW/UW are G17.1/G19.1/G18.1.
enum class Plane : std::uint8_t { XY, YZ, XZ, UV, VW, UW };

/// G93 / G94 / G95.
enum class FeedMode : std::uint8_t { UnitsPerMinute, InverseTime, UnitsPerRevolution };

/// Path control modes: G61 is exact *path* (LinuxCNC's CANON_EXACT_PATH), G61.1 exact *stop*
/// (CANON_EXACT_STOP), G64 continuous with a tolerance.
enum class MotionControl : std::uint8_t { ExactStop, ExactPath, Continuous };

enum class FeedReference : std::uint8_t { Workpiece, Xyz };

enum class SpindleDirection : std::uint8_t { Stopped, Clockwise, Counterclockwise };

/// Where a canonical call came from: the block being executed.
struct BlockOrigin {
  std::uint32_t file = 0;     ///< index into the SourceMap's file table
  std::uint32_t line = 0;     ///< 1-based source line of the block, 0 = none (start/end of run)
  std::uint32_t context = 0;  ///< interned call stack (SourceMap context), 0 = main program
  /// The block's leading N word as written ("0150" keeps its zeros), for rs274-style
  /// listings; `n_present` is false when the block does not start with N.
  bool n_present = false;
  std::uint8_t n_length = 0;
  char n_digits[22] = {};   ///< longer N words are cut (rs274 prints them whole)
};

/// ARC_FEED arguments as LinuxCNC's canonical interface defines them: the end point in the
/// active plane (first, second), the centre in the plane, the signed turn count (positive =
/// counterclockwise seen from the plane normal, e.g. G3 = +1, G2 = -1) and the end point along
/// the plane normal, plus the end of every other axis in `end`. `end` is the full end pose
/// (it repeats first/second/normal for convenience).
struct ArcFeed {
  Plane plane = Plane::XY;
  double first_end = 0, second_end = 0;
  double first_center = 0, second_center = 0;
  int rotation = 1;
  double axis_end = 0;
  Pose end;
};

/// The machine's axis coupling switched on or off by a program (the broaching codes, see
/// docs/broaching.md): which law, in program units. The machine's profile says which axes.
struct AxisCoupling {
  int law = 0;         ///< 0 off, 1 constant pitch, 2 linear pitch, 3 pitch table, 4 cam (motion::CouplingKind)
  int table = 0;       ///< 1-based table number of the profile (laws 3 and 4)
  double pitch = 0;    ///< pitch per revolution, program length units (laws 1 and 2; sign = hand)
  double rate = 0;     ///< change of pitch per unit of master travel (law 2; dimensionless)
  /// Where the law engaged, in program coordinates, when it is not where the path stands now: a
  /// program resumed at a later segment re-engages the law of a code its replay passed with the
  /// origin the code had (the replay filter sets it). False: where the path stands.
  bool has_origin = false;
  Pose origin{};
  bool operator==(const AxisCoupling&) const = default;
};

/// A machine module's own M code (a process code: EDM conditions, docs/edm.md) passed to the
/// machine as it was programmed. The words are the module's business: passed unconverted.
struct ProcessCode {
  int code = 0;  ///< the M number (M100-M199)
  double p = 0;  ///< P word (0 when absent)
  double q = 0;  ///< Q word (0 when absent)
  /// Its modal group, chosen by the module (0: a one-shot code). A code stays in force until the
  /// next of its group: a program resumed past it gets the last of each group again (ReplayFilter).
  int group = 0;
  bool operator==(const ProcessCode&) const = default;
};

/// A NURBS control point in the XY plane with its weight.
struct NurbsPoint {
  double x = 0, y = 0, weight = 1;
  bool operator==(const NurbsPoint&) const = default;
};

}  // namespace opencnc::canon
