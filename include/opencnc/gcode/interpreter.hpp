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
#include "opencnc/tools/tool_table.hpp"

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
enum class SyncKind : std::uint8_t {
  None,
  Probe,        ///< G38.x: the trip position and whether it tripped (#5061-#5070)
  Input,        ///< M66: the value read (#5399)
  ToolChange,   ///< M6, M61: where the machine stands after the change
  ProgramStop,  ///< M0, M1, M60: the operator continues (and may have changed offsets meanwhile)
};

/// "probe", "input", "tool change", "program stop" ("" for None). Any thread.
const char* to_string(SyncKind k) noexcept;

/// Values supplied with Interpreter::sync(). Positions in the program units and work
/// coordinates the interpreter used for the move (as LinuxCNC's canon reports them).
struct SyncValues {
  SyncKind kind = SyncKind::None;
  Pose probe_position{};     ///< Probe: where the probe tripped (or the move ended)
  /// Probe: the probe changed state as the move asked (contact for G38.2/G38.3, loss of
  /// contact for G38.4/G38.5); becomes #5070.
  bool probe_tripped = false;
  Pose position{};           ///< Probe/ToolChange: where the machine stands now
  double input_value = 0;    ///< Input: the value read by M66 (digital 0/1 or analog)
  /// Set by the interpreter in the request (G38.2, G38.4): a sync() without probe_tripped
  /// ends the run with `gcode.probe-no-contact` on the probe block. Ignored in sync() values.
  bool contact_required = false;
  /// Set by the interpreter: G38.2/G38.3 seek contact, G38.4/G38.5 its loss.
  bool seeks_contact = true;
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
  /// Executes at most `max_blocks` blocks (Ok: more follow), stopping at a sync point, the
  /// end or an error: what a controller streaming the program calls. Interpreter thread.
  RunStatus run(canon::Sink& sink, std::uint64_t max_blocks);
  /// Executes one line typed by the operator (no program needed; O-word calls read their
  /// subprogram from the search path). Interpreter thread; non-real-time.
  RunStatus execute_mdi(std::string_view line, canon::Sink& sink);
  /// After a sync point inside a subprogram an MDI line called: runs the call on (Ok once the
  /// line is done, NeedSync at the next sync point, Error). Interpreter thread.
  RunStatus continue_mdi(canon::Sink& sink);
  /// What the pending sync point waits for (None when not waiting).
  SyncKind pending_sync() const noexcept;
  /// The pending sync point's request: its kind and, for probes, whether contact is required
  /// (the values are what a scan would assume). Interpreter thread.
  const SyncValues& sync_request() const noexcept;
  /// Supplies machine feedback and releases the sync point. A G38.2/G38.4 result without
  /// contact ends the run (`gcode.probe-no-contact`; the next run() returns Error).
  /// Interpreter thread.
  void sync(const SyncValues& values);

  /// Where the machine is (mm and degrees, by machine axis): the interpreter's position
  /// becomes it, in program coordinates under the active offsets, as if it had moved there
  /// without output (before a program or an MDI line, after a jog). Ignored while cutter
  /// compensation is on. Interpreter thread.
  void set_machine_position(const Pose& machine_mm);
  /// A machine position (mm and degrees, by machine axis) in the program's units and active
  /// work coordinates: what sync() takes. Interpreter thread.
  Pose program_position(const Pose& machine_mm) const;
  /// The machine's tool table changed (an operator's edit, a measurement): the interpreter's
  /// copy becomes it, the tool in the spindle included. Interpreter thread.
  void set_tool_table(const std::shared_ptr<const tools::ToolTable>& table);

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
