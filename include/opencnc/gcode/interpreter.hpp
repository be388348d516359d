// SPDX-License-Identifier: GPL-3.0-or-later
// gcode::Interpreter — RS274/NGC as LinuxCNC 2.9 defines it. Reads a program (streamed
// from disk) or MDI lines and makes canonical calls on an injected canon::Sink.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "opencnc/canon/sink.hpp"
#include "opencnc/canon/source_map.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/gcode/state.hpp"

namespace opencnc::gcode {

class Engine;

/// Outcome of run(), step() and execute_mdi().
enum class RunStatus : std::uint8_t {
  Ok,         ///< step(): a block was executed; more follow
  Finished,   ///< the program ended (M2/M30 or the closing '%'); no more blocks
  NeedSync,   ///< execute mode: the next block needs machine feedback, call sync()
  Error,      ///< a G-code error; see diagnostics(). The run cannot continue.
};

/// What the machine reports at a sync point (Options::Mode::Execute).
enum class SyncKind : std::uint8_t { None, Probe, Input, ToolChange };

/// Values supplied with Interpreter::sync(). Positions in the program units and work
/// coordinates the interpreter used for the move (as LinuxCNC's canon reports them).
struct SyncValues {
  SyncKind kind = SyncKind::None;
  Pose probe_position{};     ///< Probe: where the probe tripped (or the move ended)
  bool probe_tripped = false;
  Pose position{};           ///< Probe/ToolChange: where the machine stands now
  double input_value = 0;    ///< Input: the value read by M66 (digital 0/1 or analog)
};

/// One interpreter run. Non-real-time; one thread at a time (the planner's feeder thread).
class Interpreter {
 public:
  /// Any thread; non-real-time.
  explicit Interpreter(Options options = {});
  ~Interpreter();
  Interpreter(const Interpreter&) = delete;
  Interpreter& operator=(const Interpreter&) = delete;

  /// Opens a program file (streamed, never loaded whole). Returns false and adds a
  /// diagnostic if it cannot be read. Interpreter thread; non-real-time.
  bool open(const std::string& path);
  /// Uses `text` as the program, named `name` in diagnostics and the source map.
  void open_text(std::string name, std::string text);

  /// Makes the start-up canonical calls (units, offsets, feed reference) and checks the head
  /// of the program ('%' delimiting). Called by the first run()/step() if not called before.
  /// Interpreter thread; non-real-time.
  RunStatus start(canon::Sink& sink);
  /// Runs to the end of the program, an error, or (execute mode) a sync point.
  /// Interpreter thread; non-real-time.
  RunStatus run(canon::Sink& sink);
  /// Executes one block (streaming, bounded read-ahead). Interpreter thread; non-real-time.
  RunStatus step(canon::Sink& sink);
  /// Executes one line typed by the operator (no program needed; O-word calls read their
  /// subprogram from the search path). Interpreter thread; non-real-time.
  RunStatus execute_mdi(std::string_view line, canon::Sink& sink);
  /// What the pending sync point waits for (None when not waiting).
  SyncKind pending_sync() const noexcept;
  /// Supplies machine feedback and releases the sync point. Interpreter thread.
  void sync(const SyncValues& values);

  /// The exact state now (copy). Interpreter thread; non-real-time.
  InterpState state() const;
  /// Motions emitted so far (the next segment id).
  canon::SegmentId segments() const noexcept;
  /// Errors and warnings of the run, with file, line and column.
  const Diagnostics& diagnostics() const noexcept;
  /// Files and call stacks of the run (shared with canon::Program builders).
  std::shared_ptr<canon::SourceMap> sources() const noexcept;
  const Options& options() const noexcept;

 private:
  std::unique_ptr<Engine> engine_;
};

}  // namespace opencnc::gcode
