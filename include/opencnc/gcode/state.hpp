// SPDX-License-Identifier: GPL-3.0-or-later
// InterpState — the complete interpreter state as a value: modes, positions, offsets,
// parameters, tools, call stack and loop positions. Equal states replay identically.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "opencnc/canon/types.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/vec3.hpp"
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
  Vec3 programmed{};  ///< programmed point while cutter compensation runs
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

/// Canned-cycle values that carry over from block to block (LinuxCNC's `cycle_*` settings):
/// a block that repeats the active cycle may leave out R, the bottom, P, Q and I/J/K. All in
/// program units, as the program gave them (an incremental bottom stays incremental).
struct CycleState {
  double r = 0;              ///< R plane
  double bottom = 0;         ///< bottom word of the plane's drilling axis (Z in G17)
  double p = 0;              ///< dwell (G82 G86 G88 G89, G74/G84)
  double q = 0;              ///< peck increment (G73 G83)
  double i = 0, j = 0, k = 0;   ///< G87 back-boring offsets and top
  /// Drilling-axis position before the first of a run of cycle blocks (the G98 retract
  /// height and the base of an incremental R); valid until a block moves with another code.
  double initial_level = 0;
  bool initial_level_valid = false;
  bool operator==(const CycleState&) const = default;
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

/// Fanuc coordinate transforms (G51.1 mirroring, G51 scaling, G68 rotation). Motion passes
/// through them in Fanuc's order, mirror then scale then rotate, each about a centre fixed in
/// that stage's input coordinates when it was programmed (docs/dialects.md).
struct TransformState {
  std::uint16_t mirror_axes = 0;   ///< bit per axis (Axis order) mirrored by G51.1
  Pose mirror_at{};                ///< the mirror line (coordinate) of each mirrored axis
  bool scaling = false;            ///< G51
  Pose scale_centre{};
  std::array<double, 3> scale{1.0, 1.0, 1.0};   ///< X Y Z factors (negative mirrors)
  bool rotating = false;           ///< G68
  canon::Plane rotation_plane = canon::Plane::XY;
  double rotation_centre1 = 0;     ///< centre in the plane's first and second axis
  double rotation_centre2 = 0;
  double rotation_deg = 0;         ///< counterclockwise from the first axis toward the second
  bool active() const noexcept { return mirror_axes != 0 || scaling || rotating; }
  bool operator==(const TransformState&) const = default;
};

/// A Fanuc WHILE/DO loop being run: its DO number, where its WHILE (or DO) line starts and
/// where reading continues after its END line.
struct FanucLoop {
  int id = 0;
  SourcePosition start;
  SourcePosition after_end;
  bool operator==(const FanucLoop&) const = default;
};

inline constexpr int kFanucLocalCount = 33;   ///< #1..#33, local to a G65 macro level

/// The Fanuc dialect's part of one call level (the main program or an M98/G65 call).
struct FanucFrame {
  SourcePosition body;              ///< start of the program (its O line, or the file start)
  std::uint32_t program = 0;        ///< its O number (0: the main program without one)
  std::uint32_t repeats_left = 0;   ///< M98/G65 L: runs still to come after this one
  bool macro = false;               ///< G65: own local variables #1..#33
  bool started = false;             ///< a block other than its O line has run
  std::array<double, kFanucLocalCount> saved_locals{};   ///< G65: the caller's #1..#33
  std::bitset<kFanucLocalCount + 1> saved_vacant;         ///< ... and which were vacant
  std::vector<FanucLoop> loops;     ///< DO loops running at this level, innermost last
  bool range = false;               ///< G70: a run of the caller's blocks N P .. N Q
  SourcePosition range_end;         ///< G70: the block N Q (the run ends after it)
  Pose range_return{};              ///< G70: where the tool goes back to afterwards
  bool operator==(const FanucFrame&) const = default;
};

inline constexpr int kFanucVariableCount = 1000;   ///< #0..#999 can be vacant

/// What the first block of a Fanuc two-block lathe cycle sets for the blocks after it.
struct FanucCycleSettings {
  double rough_depth = 0;        ///< G71 U(d) / G72 W(d): depth of cut (0: not set)
  double rough_retract = -1;     ///< G71/G72 R(e): retract after each cut (-1: not set)
  double groove_retract = 0;     ///< G75 R(e): retract after each peck (0: not set)
  int thread_finish_passes = 1;  ///< G76 P(m): finishing passes
  double thread_chamfer = 0;     ///< G76 P(r): pull-out length in tenths of the lead
  double thread_angle_deg = 60;  ///< G76 P(a): tool angle (infeed along half of it)
  double thread_min_depth = 0;   ///< G76 Q(dmin): smallest depth of cut
  double thread_allowance = 0;   ///< G76 R(d): finishing allowance
  bool operator==(const FanucCycleSettings&) const = default;
};

/// The Fanuc dialect's program-wide state.
struct FanucState {
  TransformState transform;
  FanucCycleSettings cycles;
  /// Macro variables without a value (Fanuc's <vacant>): #0 always, #1..#33 and #100..#999
  /// until assigned. Vacant reads as 0 in arithmetic (docs/dialects.md).
  std::bitset<kFanucVariableCount> vacant;
  double spindle_clamp_rpm = 0;     ///< G50 S / G92 S: highest spindle speed (0: none)
  bool operator==(const FanucState&) const = default;
};

/// How a call level was entered: the main program, `o<name> call` (its sub ends with endsub
/// or return) or LinuxCNC's numbered `M98 P` (its O-numbered sub ends with M99). LinuxCNC
/// refuses to mix the two styles.
enum class CallKind : std::uint8_t { Main, OWord, Numbered };

/// One level of the subprogram call stack.
struct CallFrame {
  std::string sub;                                 ///< name of the running subprogram
  CallKind kind = CallKind::Main;
  std::array<double, kSubArgumentCount> saved_args{};  ///< caller's #1..#30 (not for M98: they are global)
  NamedParameters locals;
  SourcePosition return_to;                        ///< where the caller continues
  std::uint32_t context = 0;                       ///< SourceMap context of this level
  SavedContext saved;
  /// LinuxCNC M98 L run from this level: calls still to make (-1: none). The M98 line is
  /// read again for each, as LinuxCNC does.
  std::int64_t m98_left = -1;
  /// M98 L from an MDI line, which cannot be read again: runs of this body still to come.
  std::int64_t m98_runs_left = 0;
  FanucFrame fanuc;                                ///< Fanuc dialect only
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
  SourcePosition main_start;        ///< the main program's first line (M99 repeats from here)
  std::uint64_t main_repeats = 0;   ///< times M99 sent the main program back to its start
  bool operator==(const ControlState&) const = default;
};

/// A motion that cutter compensation holds in the output queue until the corner after it is
/// known (LinuxCNC's queued canonical motion, reduced to what the corner rules read). Plane
/// coordinates: (first, second) of the active comp plane (XY: x y; XZ: z x), before the lathe
/// tool origin shift.
struct CompQueuedMove {
  enum class Kind : std::uint8_t { Traverse, Feed, Arc };
  Kind kind = Kind::Feed;
  double dir1 = 0, dir2 = 0;         ///< lines: programmed direction (a reversed end is a gouge)
  double center1 = 0, center2 = 0;   ///< arcs: centre
  double end1 = 0, end2 = 0;         ///< arcs: end (with the centre, the compensated radius)
  int turn = 0;                      ///< arcs: signed turns (G3 > 0)
  double sweep = 0;                  ///< arcs: programmed sweep (rad); 0 = corner arc
  bool operator==(const CompQueuedMove&) const = default;
};

/// Cutter compensation between blocks, beyond the modal flags: where the queued moves start
/// and what they are. Plain data, so that replay or a resume restores it exactly.
struct CompState {
  double start1 = 0, start2 = 0;     ///< plane point the queued moves start from
  bool start_valid = false;          ///< false: gouge checks of the queued moves are skipped
  std::vector<CompQueuedMove> queued;
  /// The first move of the last non-empty queue. LinuxCNC reads the queue's first entry
  /// without checking that there is one; after a stop released the queue it reads this one.
  CompQueuedMove last_first;
  bool operator==(const CompState&) const = default;
};

/// Spline state kept between blocks: the G5.2 control points collected so far (the first is
/// where the curve starts; LinuxCNC keeps them, stale ones included, until the next G5.2
/// sequence or G5.3) and the first control offset a G5 without I/J uses (minus the last
/// G5's P and Q).
struct SplineState {
  std::vector<canon::NurbsPoint> points;
  int order = 3;
  double g5_i = 0, g5_j = 0;
  bool operator==(const SplineState&) const = default;
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
  CompState comp;                                      ///< cutter compensation's held moves
  CycleState cycle;
  SplineState spline;
  FanucState fanuc;                                    ///< Fanuc dialect only
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
