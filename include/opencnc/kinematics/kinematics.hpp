// SPDX-License-Identifier: GPL-3.0-or-later
// Five-axis kinematics: joints (X Y Z and two rotary axes) ↔ the tool (its tip in the work's
// frame and its axis), for table-table, head-head and head-table machines; forward, inverse with
// the choice of solution branch, and the Jacobian. Plain data, no allocation: a stage of the tick.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/core/axes.hpp"
#include "opencnc/core/vec3.hpp"

namespace opencnc::kinematics {

/// Where the two rotary axes sit. The linear joints X Y Z always move the spindle's gauge point
/// relative to the table.
enum class Structure : std::uint8_t {
  Identity,    ///< joints are the program's coordinates (no rotary axis in the transform)
  TableTable,  ///< both rotary axes turn the table: a trunnion (A/C, B/C); the first carries the second
  HeadHead,    ///< both turn the spindle head (B/C, A/C); the first carries the second
  HeadTable,   ///< the first turns the head (B), the second the table (C)
};

/// "identity", "table-table", "head-head", "head-table".
const char* to_string(Structure s) noexcept;

/// One rotary axis of the chain, as it lies with every rotary joint at 0.
struct RotaryAxis {
  Axis joint = Axis::C;  ///< the joint that turns it (A, B or C)
  /// Its direction (a unit vector after `prepare`); a positive joint angle turns right-handed
  /// about it.
  Vec3 direction{0, 0, 1};
  /// A point on it (mm): in machine coordinates for a table axis; for a head axis relative to
  /// the spindle's gauge point, the point that X Y Z command.
  Vec3 pivot_mm{};
};

/// A machine's kinematic chain. Plain data, copied into the tick.
struct Config {
  Structure structure = Structure::Identity;
  /// TableTable and HeadHead: the outer axis first (the one on the machine's base or carriage,
  /// which carries the other); HeadTable: the head's axis first, then the table's.
  std::array<RotaryAxis, 2> rotary{};
};

/// Why a Config cannot be used, or kOk. Any thread.
enum class ConfigError : std::uint8_t {
  Ok,
  ZeroDirection,  ///< a rotary axis' direction has no length
  SameJoint,      ///< both rotary axes name the same joint
  NotRotary,      ///< a rotary axis names a linear joint
  ParallelAxes,   ///< the two directions are parallel: the tool axis could not be turned freely
};
const char* to_string(ConfigError e) noexcept;

/// Checks `c` and makes its directions unit vectors. Any thread; RT-safe.
ConfigError prepare(Config& c) noexcept;

/// The tool: its tip in the work's frame (the table's, turned back by the table's rotary axes;
/// machine coordinates when the table axes are at 0) and its axis, a unit vector from the tip
/// towards the spindle (0 0 1 with every rotary joint at 0).
struct ToolPose {
  Vec3 tip_mm{};
  Vec3 axis{0, 0, 1};
};

/// The tool's tip and axis for the joints `j` (X Y Z in mm, rotary joints in degrees) with a tool
/// `tool_length_mm` long (from the gauge point to the tip along the tool's axis). Identity: the
/// tip is X Y Z less the tool length along Z. Any thread; RT-safe.
ToolPose forward(const Config& c, const Pose& j, double tool_length_mm) noexcept;

/// What `inverse` found.
enum class Solve : std::uint8_t {
  Ok,
  Singular,     ///< the tool axis lies along a rotary axis: that axis' angle is free and was kept
  Unreachable,  ///< no rotary position turns the tool onto this axis
};

/// At most two rotary positions give one tool axis (the head or table turned over); each angle is
/// also free by whole turns, which `inverse` settles nearest to the joints it starts from.
struct Solutions {
  Solve status = Solve::Unreachable;
  int count = 0;
  std::array<Pose, 2> joints{};
};

/// Every joint position that puts the tool's tip at `tool.tip_mm` with its axis along `tool.axis`
/// (normalised here; zero length: Unreachable), the rotary angles each taken by whole turns
/// nearest to `from`'s; the other joints (U V W …) are `from`'s. Identity: one solution, X Y Z the
/// tip plus the tool length along Z, the rotary joints `from`'s. Any thread; RT-safe.
Solutions inverse_all(const Config& c, const ToolPose& tool, double tool_length_mm,
                      const Pose& from) noexcept;

/// The solution of `inverse_all` with the least rotary motion from `from` (the sum of the two
/// angles' changes), or `from` itself when Unreachable. Any thread; RT-safe.
struct Inverse {
  Solve status = Solve::Unreachable;
  Pose joints{};
};
Inverse inverse(const Config& c, const ToolPose& tool, double tool_length_mm, const Pose& from) noexcept;

/// ∂(tip, axis)/∂(X, Y, Z, first rotary, second rotary) at `j`: rows tip x y z, axis x y z;
/// columns per mm and per degree. Identity: the rotary columns are zero. Any thread; RT-safe.
using Jacobian = std::array<std::array<double, 5>, 6>;
Jacobian jacobian(const Config& c, const Pose& j, double tool_length_mm) noexcept;

}  // namespace opencnc::kinematics
