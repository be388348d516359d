// SPDX-License-Identifier: GPL-3.0-or-later
// Extension points of the interpreter: G/M code handlers (canned cycles, threading,
// probing, splines, lathe cycles), the motion stage where cutter compensation sits, and the
// coordinate transform a Fanuc dialect applies before canonical output.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/block.hpp"
#include "opencnc/gcode/error_codes.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

/// Centre and signed turn count of a programmed arc, in the active plane's coordinates.
struct ArcCentre {
  double first = 0, second = 0;
  int turn = 0;   ///< G3: +turns, G2: -turns
};

/// What an extension may do while the interpreter executes a block. Implemented by the
/// interpreter; valid only during the call it is passed to. Interpreter thread only.
class ExecContext {
 public:
  virtual ~ExecContext() = default;
  /// The live interpreter state (positions in program units, active coordinate system).
  virtual InterpState& state() = 0;
  virtual const Options& options() const = 0;
  /// End point of `block`'s axis words under the current distance mode, G53 and polar
  /// rules (LinuxCNC's find_ends), in program coordinates.
  virtual Pose end_point(const Block& block) = 0;
  /// Canonical output after the interpreter's own stages (transform, axis map, segment ids,
  /// source origin). Motions through here bypass the motion stage (a compensator's own
  /// output); feed, spindle, dwell and comment calls are queued while the queue is open.
  virtual canon::Sink& output() = 0;
  /// A straight move through the motion stage (the compensator, while compensation is on);
  /// updates the current position.
  virtual void straight(bool rapid, const Pose& end) = 0;
  /// An arc with final geometry, straight to output; updates the current position.
  virtual void arc(const canon::ArcFeed& arc) = 0;
  /// Centre and turn of the arc `block` programs (motion 20/30) from `start` to `end`, by
  /// LinuxCNC's rules: R or I/J/K words of the active plane, P turns, its tolerances and
  /// errors. In inverse-time mode it also sets the feed rate for that arc.
  virtual ArcCentre arc_centre(const Block& block, int motion, const Pose& start, const Pose& end) = 0;
  /// The core's G0, G1, G2 or G3 (`motion` 0, 10, 20, 30) with the words of `words`, as if a
  /// block had programmed them under the current modes: the core's checks (feed rate, arc
  /// centre and radius, inverse time), end points by the distance modes, and the motion
  /// stage while compensation is on. LinuxCNC's G70-G72 make their moves this way.
  virtual void programmed_move(int motion, const Block& words) = 0;
  /// Reads subprogram `name` the way LinuxCNC's G70-G72 read their profile: the sub is called,
  /// its O-word lines run (loops, conditions, nested calls) and parameter assignments take
  /// effect, and every other block is parsed and checked, then handed to `visit` instead of
  /// being executed. Returns when the sub returns; reading then goes on after the current
  /// block. `extra_letters` (bit letter - 'a') are letter words accepted while reading
  /// whatever the machine's axes (LinuxCNC reads A, C, U and W there). Afterwards the output
  /// belongs to the current block again, with the N label of the last line read (as rs274
  /// prints it); `block` passed to the handler is valid again.
  virtual void read_subprogram(const std::string& name, std::uint32_t extra_letters,
                               const std::function<void(const Block&)>& visit) = 0;
  /// Reads the blocks numbered N`first` to N`last` of the running program the way Fanuc's
  /// G71/G72 read their finishing shape (Fanuc dialect): each block is parsed, its Fanuc words
  /// translated (U/W from the current position, which the visitor keeps at the shape's point)
  /// and checked, then handed to `visit` instead of being executed. Macro statements,
  /// assignments and calls in the range are errors; so is a range whose N`last` comes before
  /// N`first` (`what` names the cycle in messages). Errors raised while a block is visited
  /// point at that block. Afterwards the output belongs to the current block again, and the
  /// program goes on after N`last` when the range follows the current block with nothing but
  /// blank and comment lines between them (Fanuc passes over the shape after roughing), else
  /// after the current block.
  virtual void read_block_range(std::int64_t first, std::int64_t last, std::string_view what,
                                const std::function<void(const Block&)>& visit) = 0;
  /// LinuxCNC keeps a queue of canonical calls while cutter compensation is on so that a
  /// move's end can still be changed; open it, then flush it when the moves are final.
  virtual void open_queue() = 0;
  virtual void flush_queue() = 0;
  virtual std::size_t queued() const = 0;
  /// Moves the end of every queued motion, in `plane`, to (first, second): a compensated
  /// move into a corner is settled only when the move out of it is known.
  virtual void move_queued_end(canon::Plane plane, double first, double second) = 0;
  /// The block needs machine feedback before the next one (a probe move, an input wait).
  /// Execute mode: the interpreter stops until Interpreter::sync(); scan mode: `assumed`
  /// is applied at once, as the stand-alone rs274 would.
  virtual void request_sync(const SyncValues& assumed) = 0;
  /// Ends the block with a G-code error (never returns).
  [[noreturn]] virtual void error(ErrorCode code, const std::string& message) = 0;
};

/// Implements G or M codes the interpreter core does not. Registered per code in
/// Extensions; called at the code's place in LinuxCNC's order of execution (motion codes at
/// the motion step, after all modal settings of the block).
class CodeHandler {
 public:
  virtual ~CodeHandler() = default;
  /// A problem found by check().
  struct Rejection {
    ErrorCode code;
    std::string message;
  };
  /// Checks of the block's words that LinuxCNC makes while reading (before anything
  /// executes). Returns the problem, which ends the run as a G-code error on the block;
  /// the default accepts every block.
  virtual std::optional<Rejection> check(const Block& /*block*/, int /*code*/, const InterpState& /*state*/) const {
    return std::nullopt;
  }
  virtual void execute(ExecContext& ctx, const Block& block, int code) = 0;

  /// What the core needs to read a code it does not know itself (a dialect's own codes, such
  /// as Fanuc's G68): its modal group (GGroup or MGroup; -1 = unknown), the letter words it
  /// takes (bit letter - 'a'; the core's rules for unused words skip them), whether the
  /// block's axis words are its data (as for G92) rather than a motion, and whether the
  /// handler checks all of its block's words itself (the core's word and axis rules are
  /// skipped, as for a dialect's own version of a cycle the core knows, such as Fanuc's G76).
  struct Traits {
    int group = -1;
    std::uint32_t words = 0;
    bool axis_words = false;
    bool all_words = false;
  };
  virtual Traits traits(int /*code*/) const { return {}; }
};

/// Where cutter radius compensation sits: every programmed straight and arc move in the
/// active plane passes through here while compensation is on; the interpreter turns it on
/// and off with G41/G42/G40 (registered as CodeHandlers by the compensation module).
class MotionStage {
 public:
  virtual ~MotionStage() = default;
  /// A programmed G0/G1 to `end` (program coordinates); must update state().position.
  virtual void straight(ExecContext& ctx, bool rapid, const Pose& end) = 0;
  /// A programmed G2/G3 (`motion` 20/30) to `end`; the centre comes from the block's R or
  /// I/J/K words, relative to state().position.programmed (LinuxCNC's convention).
  virtual void arc(ExecContext& ctx, const Block& block, int motion, const Pose& end) = 0;
  /// Release pending moves as they stand (M0, M1, M2, M30, M60; G40 is a CodeHandler).
  virtual void finish(ExecContext& ctx) = 0;
  /// The length units changed while compensating (G20/G21); lengths held between blocks
  /// (InterpState::comp) must be multiplied by `factor`. The output queue is converted by
  /// the interpreter.
  virtual void rescale(ExecContext& /*ctx*/, double /*factor*/) {}
};

/// Rotation, scaling and mirroring (Fanuc G68/G51/G51.1), applied to motion end points and
/// arcs in program coordinates before axis mapping and canonical output. The transform keeps
/// no state of its own: what G68 and the like set lives in the InterpState it is given, so
/// one Extensions object serves any number of interpreters.
class CoordinateTransform {
 public:
  virtual ~CoordinateTransform() = default;
  virtual bool active(const InterpState& state) const = 0;
  virtual Pose point(const InterpState& state, const Pose& p) const = 0;
  /// Transforms an arc in place; may throw GcodeError when the arc cannot stay an arc.
  virtual void arc(const InterpState& state, canon::ArcFeed& arc) const = 0;
};

/// The registry handed to the interpreter through Options::extensions.
struct Extensions {
  std::array<std::shared_ptr<CodeHandler>, 1000> g{};   ///< by G code ×10
  std::array<std::shared_ptr<CodeHandler>, 200> m{};    ///< by M code
  std::shared_ptr<MotionStage> compensator;             ///< used while CutterComp != Off
  std::shared_ptr<CoordinateTransform> transform;
};

}  // namespace opencnc::gcode
