// SPDX-License-Identifier: GPL-3.0-or-later
// Extension points of the interpreter: G/M code handlers (canned cycles, threading,
// probing, splines, lathe cycles), the motion stage where cutter compensation sits, and the
// coordinate transform a Fanuc dialect applies before canonical output.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/block.hpp"
#include "opencnc/gcode/error_codes.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

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
  /// LinuxCNC keeps a queue of canonical calls while cutter compensation is on so that a
  /// move's end can still be changed; open it, then flush it when the moves are final.
  virtual void open_queue() = 0;
  virtual void flush_queue() = 0;
  virtual std::size_t queued() const = 0;
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
  /// Finish pending moves (G40, M2/M30, a tool change).
  virtual void finish(ExecContext& ctx) = 0;
};

/// Rotation, scaling and mirroring (Fanuc G68/G51/G51.1), applied to motion end points and
/// arcs in program coordinates before axis mapping and canonical output.
class CoordinateTransform {
 public:
  virtual ~CoordinateTransform() = default;
  virtual bool active() const = 0;
  virtual Pose point(const Pose& p) const = 0;
  /// Transforms an arc in place; may throw GcodeError when the arc cannot stay an arc.
  virtual void arc(canon::ArcFeed& arc) const = 0;
};

/// The registry handed to the interpreter through Options::extensions.
struct Extensions {
  std::array<std::shared_ptr<CodeHandler>, 1000> g{};   ///< by G code ×10
  std::array<std::shared_ptr<CodeHandler>, 200> m{};    ///< by M code
  std::shared_ptr<MotionStage> compensator;             ///< used while CutterComp != Off
  std::shared_ptr<CoordinateTransform> transform;
};

}  // namespace opencnc::gcode
