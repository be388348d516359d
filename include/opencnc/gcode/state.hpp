// SPDX-License-Identifier: GPL-3.0-or-later
// InterpState — the complete interpreter state as a value: modes, positions, offsets,
// parameters, tools, call stack and loop positions. Equal states replay identically.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "opencnc/canon/types.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/tools/tool_table.hpp"

namespace opencnc::gcode {

inline constexpr int kParameterCount = 5602;   ///< #1..#5601 (LinuxCNC's numbered parameters)
inline constexpr int kSubArgumentCount = 30;   ///< #1..#30 are a subprogram's arguments

enum class DistanceMode : std::uint8_t { Absolute, Incremental };
enum class CutterComp : std::uint8_t { Off, Left, Right };
enum class RetractMode : std::uint8_t { OldZ, RPlane };
enum class SpindleMode : std::uint8_t { Rpm, ConstantSurface };

/// Every modal group and the modal machine settings (feed, speed, coolant, overrides).
struct ModalState {
  int motion = 800;                 ///< active motion G code ×10 (800 = G80, -1 = none)
  canon::Plane plane = canon::Plane::XY;
  canon::Units units = canon::Units::Mm;
  DistanceMode distance = DistanceMode::Absolute;
  DistanceMode ijk_distance = DistanceMode::Incremental;
  canon::FeedMode feed_mode = canon::FeedMode::UnitsPerMinute;
  CutterComp cutter_comp = CutterComp::Off;
  bool comp_first_move = true;      ///< next move starts compensation
  bool arc_not_allowed = false;     ///< the move after G40 must be straight
  double comp_radius = 0;
  int comp_orientation = 0;
  int tool_length_mode = 490;       ///< G43 / G43.1 / G43.2 / G49 ×10
  int coord_system = 1;             ///< 1..9 = G54..G59.3
  canon::MotionControl control = canon::MotionControl::Continuous;
  double path_tolerance = 0;        ///< G64 P (program units)
  double naivecam_tolerance = 0;    ///< G64 Q
  RetractMode retract = RetractMode::RPlane;
  SpindleMode spindle_mode = SpindleMode::Rpm;
  bool lathe_diameter = false;      ///< G7
  double feed_rate = 0;
  double spindle_speed = 0;
  canon::SpindleDirection spindle = canon::SpindleDirection::Stopped;
  bool mist = false;
  bool flood = false;
  bool feed_override = true;
  bool speed_override = true;
  bool adaptive_feed = false;
  bool feed_hold = true;

  bool operator==(const ModalState&) const = default;
};

/// Where the tool is and which offsets apply. All in the current program units; `current`
/// is in the active coordinate system (after G5x, G92, rotation and tool length offset).
struct PositionState {
  Pose current{};
  Pose origin_offset{};      ///< active G5x origin
  Pose axis_offset{};        ///< G92 / G52
  Pose tool_offset{};        ///< tool length offset (G43...)
  double rotation_xy_deg = 0;
  std::array<double, 3> programmed{};  ///< programmed point while cutter compensation runs
  /// The position as the canonical calls state it: the last motion's end, moved when G5x or
  /// G92 offsets or the units change (not by rotation or tool offsets). After a tool change
  /// the scan mode continues from here, as the stand-alone rs274 does.
  Pose canon_position{};
  Pose canon_g5x{};
  Pose canon_g92{};

  bool operator==(const PositionState&) const = default;
};

/// The tool in the spindle, the prepared tool and the interpreter's copy of the tool table
/// (entry 0 is the spindle; G10 L1/L10/L11 edit this copy).
struct ToolState {
  std::vector<tools::ToolEntry> table;   ///< [0] = spindle, [k] = table index k
  int selected_index = -1;               ///< index prepared by T (-1: none)
  int selected_tool = 0;
  int current_index = 1;                 ///< index whose tool is in the spindle
  bool operator==(const ToolState&) const = default;
};

/// A named parameter (#<name>); names are stored lowercase, as the program reads them.
struct NamedValue {
  double value = 0;
  bool set = false;          ///< false: declared by an assignment not yet applied
  bool operator==(const NamedValue&) const = default;
};
using NamedParameters = std::map<std::string, NamedValue, std::less<>>;

/// A place to continue reading: file (SourceMap index), byte offset, line number.
struct SourcePosition {
  std::uint32_t file = 0;
  std::uint64_t offset = 0;
  std::uint32_t line = 0;
  bool operator==(const SourcePosition&) const = default;
};

/// Modes saved by M70/M73 for M72 or the automatic restore on return, as LinuxCNC records
/// them: the active G code of each group (×10), the active M codes, feed and speed.
struct SavedContext {
  bool valid = false;
  bool restore_on_return = false;
  std::array<int, 16> g{};   ///< LinuxCNC's active G-code slots (3 plane .. 15 lathe mode)
  std::array<int, 9> m{};    ///< LinuxCNC's active M-code slots (2 spindle .. 8 feed hold)
  double feed = 0;
  double speed = 0;
  bool operator==(const SavedContext&) const = default;
};

/// One level of the subprogram call stack.
struct CallFrame {
  std::string sub;                                 ///< name of the running subprogram
  std::array<double, kSubArgumentCount> saved_args{};  ///< caller's #1..#30
  NamedParameters locals;
  SourcePosition return_to;                        ///< where the caller continues
  std::uint32_t context = 0;                       ///< SourceMap context of this level
  SavedContext saved;
  bool operator==(const CallFrame&) const = default;
};

enum class LabelKind : std::uint8_t { Sub, Do, While, Repeat, If };

/// An O-word label met so far (loops keep their start here).
struct LabelInfo {
  LabelKind kind = LabelKind::Sub;
  SourcePosition at;                 ///< the line that defines the label
  std::int64_t repeat_left = -1;     ///< `repeat`: iterations still to run (-1: not started)
  bool operator==(const LabelInfo&) const = default;
};

/// O-word control flow: labels, what the reader is skipping to, if/loop flags.
struct ControlState {
  std::map<std::string, LabelInfo, std::less<>> labels;   ///< key: "sub#label" or sub name
  std::string skipping_to;          ///< skip lines until this label ("" = not skipping)
  std::string seeking_sub;          ///< skip until `o<name> sub`
  std::uint32_t skip_start_line = 0;
  bool defining_sub = false;        ///< passing over a sub definition
  std::string defining_name;
  bool executed_if = false;
  bool doing_break = false;
  bool doing_continue = false;
  double return_value = 0;
  bool value_returned = false;
  bool operator==(const ControlState&) const = default;
};

/// The exact interpreter state. Returned by Interpreter::state(); compare with == or by
/// digest(). Non-real-time (holds strings and maps); cheap enough to take per block.
struct InterpState {
  ModalState modal;
  PositionState position;
  ToolState tool;
  std::array<double, kParameterCount> parameters{};   ///< #0..#5601
  NamedParameters globals;                             ///< #<_name>
  std::vector<CallFrame> frames;                       ///< [0] = main program
  ControlState control;
  SourcePosition next;                                 ///< next line to read
  bool percent_delimited = false;                      ///< file started with '%'
  bool ended = false;                                  ///< M2/M30 or closing '%' reached
  std::uint64_t blocks_executed = 0;
  std::uint64_t loop_iterations = 0;
  std::uint64_t segments = 0;                          ///< motions emitted so far

  bool operator==(const InterpState&) const = default;
  /// A stable 64-bit hash of everything above (FNV-1a over a fixed field order; doubles by
  /// bit pattern). Same state → same digest on every run and machine. Any thread.
  std::uint64_t digest() const noexcept;
};

}  // namespace opencnc::gcode
