// SPDX-License-Identifier: GPL-3.0-or-later
// canon::Program — the expanded motions of a program in machine coordinates, with the
// non-motion actions between them and a source map. Cheap to hold a million segments.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/canon/source_map.hpp"
#include "opencnc/canon/types.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/chunked_vector.hpp"
#include "opencnc/core/vec3.hpp"

namespace opencnc::canon {

enum class MoveKind : std::uint8_t {
  Traverse,   ///< G0: at rapid rate
  Feed,       ///< G1 (and straight segments of cycles, cutter compensation, ...)
  Arc,        ///< G2/G3 arc or helix; details in Program::arc()
  Probe,      ///< G38.x straight probe
  RigidTap,   ///< G33.1: two moves, in to the bottom and (kTapReturn) back out to the start;
              ///< their Program::feed() is the way out's spindle speed factor (G33.1 I)
};

/// Bits of Move::flags.
enum MoveFlag : std::uint8_t {
  kInverseTime = 1u << 0,      ///< feed is 1/minutes for this move (G93)
  kPerRevolution = 1u << 1,    ///< feed is per spindle revolution (G95)
  kSpindleSynced = 1u << 2,    ///< position locked to the spindle (G33, G76, G33.1)
  kCurveChord = 1u << 3,       ///< a chord of a spline (NURBS_FEED) split by ProgramBuilder
  kTapReturn = 1u << 4,        ///< RigidTap: the way out, from the bottom back to the start
};

/// One motion, 16 bytes. The end pose is stored separately (Program::end()); the start is
/// the previous motion's end (or Program::start() for the first).
struct Move {
  MoveKind kind = MoveKind::Feed;
  std::uint8_t flags = 0;
  std::uint16_t reserved = 0;
  std::uint32_t context = 0;  ///< SourceMap context (call stack); its body file is the source file
  std::uint32_t line = 0;     ///< source line of the block that produced the move
  std::uint32_t param = 0;    ///< Arc: index into arcs; others: index into feeds
};
static_assert(sizeof(Move) == 16);

/// Geometry of an arc or helix in machine coordinates (mm), in the plane's axis triple
/// (X,Y,Z for XY/YZ/XZ; U,V,W for UV/VW/UW).
struct ArcGeometry {
  Vec3 center{0, 0, 0};          ///< on the plane through the start point
  Vec3 normal{0, 0, 1};          ///< unit normal; rotation is counterclockwise about it
  std::int32_t turns = 1;        ///< LinuxCNC's rotation: |turns|-1 extra full circles; sign = direction
  Plane plane = Plane::XY;
  std::uint32_t feed = 0;        ///< index into feeds
};

/// A feed value as programmed (converted to mm where it is a length rate).
struct FeedValue {
  double value = 0;  ///< mm/min, mm/rev, or 1/min (inverse time)
};

enum class ActionKind : std::uint8_t {
  Dwell,         ///< value = seconds
  SpindleSpeed,  ///< index = spindle, value = rpm; under G96 (index2 = 1) the surface
                 ///< speed in mm/min, its pose the X of the spindle axis (mm, machine)
  SpindleCw,
  SpindleCcw,
  SpindleStop,    ///< index = spindle
  SpindleMode,    ///< value = css max rpm, 0 = G97
  SpindleOrient,  ///< value = degrees, index2 = direction
  SelectTool,
  ChangeTool,
  ChangeToolNumber,    ///< index = tool
  ToolLengthOffset,    ///< pose = offset (mm)
  WorkOffset,          ///< index = 1..9, pose = G5x offset (mm)
  G92Offset,           ///< pose = G92/G52 offset (mm)
  XyRotation,          ///< value = degrees
  MotionControl,       ///< index = MotionControl, value = tolerance (mm)
  NaiveCamTolerance,   ///< value = mm
  SpeedFeedSyncStart,  ///< value = mm per revolution, index2 = velocity mode
  SpeedFeedSyncStop,
  MistOn,
  MistOff,
  FloodOn,
  FloodOff,
  FeedOverrideEnable,
  FeedOverrideDisable,
  SpeedOverrideEnable,
  SpeedOverrideDisable,  ///< index = spindle
  AdaptiveFeedEnable,
  AdaptiveFeedDisable,
  FeedHoldEnable,
  FeedHoldDisable,
  MotionOutputBit,  ///< index = output, index2 = 1 set / 0 clear (synchronised with motion)
  AuxOutputBit,     ///< index = output, index2 = 1 set / 0 clear (immediate)
  MotionOutputValue,
  AuxOutputValue,  ///< index = output, value
  WaitInput,       ///< index = input, index2 = mode (L), value = timeout s; text = "digital"/"analog"
  ProbeOn,
  ProbeOff,
  Message,  ///< text
  Comment,  ///< text
  ProgramStop,
  OptionalStop,
  PalletShuttle,
  ProgramEnd,
  /// Not from the interpreter: the controller's hand-axis pass (drill::HandAxisFilter) puts
  /// it where a move of a hand-fed axis was. index = axis, value = machine position, index2 = +1:
  /// a retract (the move went in +), 0: a plunge.
  HandAxisWait,
  /// The broaching codes' coupling (canon::AxisCoupling): index = law (0 off), index2 = table,
  /// value = pitch (mm), action pose [0] = pitch rate, `origin` = 1 + the action pose of the
  /// law's origin in machine coordinates (0: where the path stands). The motion stops exactly there.
  AxisCoupling,
  /// A machine module's process code (canon::ProcessCode): index = code, value = P, action pose
  /// [0] = Q. The motion stops exactly there.
  ProcessCode,
};

/// A non-motion action executed before move `before_move` (== move count: after the last).
struct Action {
  ActionKind kind = ActionKind::Comment;
  std::int32_t index = 0;
  std::int32_t index2 = 0;
  std::uint32_t before_move = 0;
  std::uint32_t context = 0;
  std::uint32_t line = 0;
  double value = 0;
  std::uint32_t text = 0;   ///< index into texts (Message/Comment)
  std::uint32_t pose = 0;   ///< index into poses of actions (offsets)
  std::uint32_t origin = 0;  ///< AxisCoupling: 1 + index into poses of the law's origin (0: none)
};

/// Whether `a` refers to a pose of its program's action poses (`pose`): the offsets, a surface
/// speed's spindle axis (index2 = 1), a coupling's rate, a process code's Q.
constexpr bool has_pose(const Action& a) noexcept {
  switch (a.kind) {
    case ActionKind::ToolLengthOffset:
    case ActionKind::WorkOffset:
    case ActionKind::G92Offset:
    case ActionKind::AxisCoupling:
    case ActionKind::ProcessCode:
      return true;
    case ActionKind::SpindleSpeed:
      return a.index2 == 1;
    default:
      return false;
  }
}

/// The expanded program. Positions in machine coordinates (mm, degrees) with every offset,
/// unit conversion and rotation applied. Built by canon::ProgramBuilder; read by the planner,
/// the summary, the path index and the plotter. Non-real-time; not thread-safe while built,
/// safe to share read-only afterwards.
///
/// A program may also be a window on a stream (the controller's execution of a file): moves
/// and actions are appended while the front is read, and what every reader has passed is
/// released (release_before). Indices never change; reading a released move or action is a
/// bug. Release assumes the side tables are referenced in append order, as ProgramBuilder
/// does (a move refers to the latest feed or a newer one, an action's text and pose are added
/// just before it).
class Program {
 public:
  explicit Program(AxisMask axes = kXyzabc);

  AxisMask axes() const noexcept { return axes_; }
  /// Number of stored axis values per pose (the axes in the mask).
  int stride() const noexcept { return stride_; }

  std::size_t size() const noexcept { return moves_.size(); }
  bool empty() const noexcept { return moves_.empty(); }
  const Move& move(SegmentId id) const noexcept { return moves_[id]; }
  /// End pose of move `id` (axes outside the mask are 0).
  Pose end(SegmentId id) const noexcept;
  /// One coordinate of end(id), without building the pose.
  double end_coord(SegmentId id, Axis axis) const noexcept {
    if (!axes_.has(axis)) return 0.0;
    return coords_[static_cast<std::size_t>(id) * static_cast<std::size_t>(stride_) + axis_slots_[index(axis)]];
  }
  /// Start pose of move `id`.
  Pose start_of(SegmentId id) const noexcept { return id == 0 ? start_ : end(id - 1); }
  const Pose& start() const noexcept { return start_; }
  const ArcGeometry& arc(SegmentId id) const noexcept { return arcs_[moves_[id].param]; }
  double feed(SegmentId id) const noexcept;

  /// Actions appended so far (the index of the next one).
  std::size_t action_count() const noexcept { return actions_.size(); }
  const Action& action(std::size_t index) const noexcept { return actions_[index]; }
  const std::string& text(std::uint32_t index) const { return texts_.at(index - first_text_); }
  const Pose& action_pose(std::uint32_t index) const { return action_poses_[index]; }

  /// Streams: frees the moves before `move` and the actions before `action` (whole chunks of
  /// them, with the arcs, feeds, texts and poses only they refer to). The first move kept
  /// still has its predecessor's end (start_of) unless `move` is 0.
  void release_before(std::size_t move, std::size_t action);
  /// The first move (action) index still held (0 unless released).
  std::size_t first_held_move() const noexcept { return moves_.first_held(); }
  std::size_t first_held_action() const noexcept { return actions_.first_held(); }

  /// Segment ids and move indices. The interpreter numbers its motions (segment ids, what
  /// replay and breakpoints use); the program numbers its moves. They differ where one
  /// segment became several moves (a spline split into chords) and by the id of the first
  /// move (replay to segment k starts at k). Both are O(log e), e = number of split segments.
  SegmentId segment_of(std::size_t move) const noexcept;
  /// First move of segment `segment` (moves of a split segment follow it in order).
  std::size_t first_move_of(SegmentId segment) const noexcept;
  /// Number of moves segment `segment` became (1 unless it was split).
  std::size_t moves_of(SegmentId segment) const noexcept;

  const SourceMap& sources() const noexcept { return *sources_; }
  std::shared_ptr<const SourceMap> sources_ptr() const noexcept { return sources_; }
  /// Source file index of a move (the body file of its context, or the main file).
  std::uint32_t file_of(SegmentId id) const;

  /// Bytes held by the program's storage (moves, poses, arcs, feeds, actions).
  std::size_t memory_bytes() const noexcept;

  // --- building (used by ProgramBuilder) ----------------------------------------------
  void set_start(const Pose& p) noexcept { start_ = p; }
  void set_sources(std::shared_ptr<const SourceMap> s) noexcept { sources_ = std::move(s); }
  SegmentId append(const Move& m, const Pose& end);
  /// Appends a move ending at `end` and returns it for the caller to fill in (every member):
  /// ProgramBuilder's way, which spares copying a Move it has just built.
  Move& append(const Pose& end);
  /// Changes one coordinate of move `id`'s end (a pass over moves just appended, e.g. the
  /// controller's hand-axis pass; `axis` must be in the mask).
  void set_end_coord(SegmentId id, Axis axis, double value) noexcept {
    coords_[static_cast<std::size_t>(id) * static_cast<std::size_t>(stride_) + axis_slots_[index(axis)]] = value;
  }
  std::uint32_t add_arc(const ArcGeometry& a);
  std::uint32_t add_feed(double value);
  void add_action(const Action& a);
  std::uint32_t add_text(std::string s);
  std::uint32_t add_action_pose(const Pose& p);
  /// The segment id of the first move (default 0).
  void set_first_segment(SegmentId id) noexcept { first_segment_ = id; }
  /// Segment `segment` was appended as `moves` moves starting at move index `first_move`
  /// (call in segment order, after appending them).
  void note_split(SegmentId segment, std::size_t first_move, std::size_t moves);

 private:
  AxisMask axes_;
  int stride_ = 0;
  std::uint8_t axis_slots_[kAxisCount] = {};  ///< stored slot of each axis in the mask
  std::uint8_t slot_axes_[kAxisCount] = {};   ///< axis stored in each slot
  Pose start_{};
  ChunkedVector<Move> moves_;
  ChunkedVector<double, 16> coords_;
  ChunkedVector<ArcGeometry, 12> arcs_;
  ChunkedVector<double, 12> feeds_;
  ChunkedVector<Action, 12> actions_;
  std::deque<std::string> texts_;
  std::uint32_t first_text_ = 0;  ///< index of texts_.front()
  ChunkedVector<Pose, 10> action_poses_;
  // The lowest side-table entries the first move (action) of each chunk and everything after
  // it may refer to, noted when it was appended: the newest entry then (its own arc, feed,
  // text or pose is added just before it). release_before frees below them.
  struct MoveFloor {
    std::size_t arc = 0, feed = 0;
  };
  struct ActionFloor {
    std::size_t text = 0, pose = 0;
  };
  std::vector<MoveFloor> move_floors_;      ///< per chunk of moves_
  std::vector<ActionFloor> action_floors_;  ///< per chunk of actions_
  std::shared_ptr<const SourceMap> sources_;
  // A segment split into several moves; `extra` counts the moves added by it and all splits
  // before it, so that later ids map by subtraction.
  struct Split {
    SegmentId segment;
    std::size_t first_move;
    std::size_t moves;
    std::size_t extra;
  };
  std::vector<Split> splits_;
  SegmentId first_segment_ = 0;
};

}  // namespace opencnc::canon
