// SPDX-License-Identifier: GPL-3.0-or-later
// Interpreter options: dialect, axes, axis-letter map, search path, tools, runaway limits.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/canon/types.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/tools/tool_table.hpp"

namespace opencnc::gcode {

struct Extensions;

/// The G-code language the interpreter reads: LinuxCNC 2.9's RS274/NGC, or Fanuc-style
/// G-code (O-numbered programs, M98/M99, G65, GOTO/IF/WHILE, macro variables, G68/G51/G51.1;
/// docs/dialects.md). The Fanuc dialect's codes come with standard_extensions(Dialect::Fanuc).
enum class Dialect : std::uint8_t { LinuxCnc, Fanuc };

/// The kind of machine a program is for. Fanuc programs read differently on lathes: X words
/// are diameters, U and W are incremental X and Z, T0101 names tool and offset, G50 S clamps
/// the spindle, G98/G99 are feed per minute/revolution and ZX (G18) is the default plane.
enum class MachineKind : std::uint8_t { Mill, Lathe };

/// Execute: stop before a block that needs machine feedback (probe result, M66 input,
/// tool change) until the caller supplies it with Interpreter::sync(). Scan: never stop;
/// assume what LinuxCNC's stand-alone `rs274` assumes (a probe reports the programmed end
/// with #5070 = 0 and backs off towards the start, inputs read 0).
enum class Mode : std::uint8_t { Scan, Execute };

/// What a scan assumes the machine answers at sync points. Rs274 is what the stand-alone rs274
/// assumes (above). Other gives other answers — a probe trips halfway with #5070 = 1, a digital
/// input reads the opposite of #5399, an analog one #5399 + 1 — so that comparing two scans shows
/// which moves rest on an assumed value (the controller's preflight does).
enum class ScanAssumption : std::uint8_t { Rs274, Other };

/// Runaway protection: exceeding any limit ends the run with a `gcode.limit-*` error that
/// names the limit and the line. Zero means "use the default".
struct Limits {
  std::uint64_t max_blocks = 200'000'000;           ///< blocks executed (loop bodies count each time)
  std::uint64_t max_loop_iterations = 50'000'000;   ///< jumps back to a loop start, whole run
  std::uint32_t max_call_depth = 10;                ///< nested subprogram calls (LinuxCNC allows 10)
  std::uint64_t max_repeat_count = 10'000'000;      ///< the count of one `repeat [n]`
  std::uint64_t max_segments = 500'000'000;         ///< motions emitted
  std::uint64_t max_skipped_lines = 200'000'000;    ///< lines read while seeking a label or a sub
  /// Scan mode with MainM99::Repeat: times an endless program may start again before the scan
  /// stops with gcode.limit-main-repeats (execute mode repeats until the caller stops).
  std::uint64_t max_main_repeats = 100;
  /// Scan mode: CPU seconds of the interpreter's thread after which the scan stops with
  /// gcode.limit-time (an endless loop refused in seconds, not after the block limits' minutes).
  /// 0: no bound (the default: `check`, `scan` and the controller's preflight set one).
  double max_seconds = 0;
};

/// What M99 in the main program does (LinuxCNC dialect; the Fanuc dialect's M99 is its own).
/// End: the program ends as with M2, what LinuxCNC's stand-alone `rs274` does. Repeat: reading
/// starts again at the first line with the state as it is, what LinuxCNC's task does: an
/// endless program (a warm-up cycle, a bar feeder), stopped by the operator or by a `/M30`.
/// In execute mode every pass starts the block and loop counts of the limits afresh.
enum class MainM99 : std::uint8_t { End, Repeat };

/// Where M6 takes the machine before the change (the profile's [tool_change], docs/tool-change.md):
/// the axes in `axes` go at rapid to `machine` (machine coordinates in mm, degrees for rotary
/// axes, as G53 takes them: the spindle ends there whatever the offsets and the tool), the others
/// stay. With `z_first` Z goes there alone first, then the others together. No axes: M6 does not
/// move (LinuxCNC's rs274 without TOOL_CHANGE_POSITION).
struct ToolChangePosition {
  AxisMask axes;
  Pose machine{};
  bool z_first = true;
};

/// Everything the interpreter is configured with. Plain data; copy freely.
struct Options {
  Dialect dialect = Dialect::LinuxCnc;
  MachineKind machine = MachineKind::Mill;   ///< used by the Fanuc dialect
  Mode mode = Mode::Scan;
  ScanAssumption scan_assumption = ScanAssumption::Rs274;
  /// Axes the machine has; an axis word outside the mask is an error (as in rs274, whose
  /// default is XYZABC).
  AxisMask axes = kXyzabc;
  /// Program axis letter → machine axis (axis exchange). Identity by default. Applied to
  /// canonical output only; the program's own coordinates are unaffected.
  std::array<Axis, kAxisCount> axis_map = {Axis::X, Axis::Y, Axis::Z, Axis::A, Axis::B,
                                           Axis::C, Axis::U, Axis::V, Axis::W};
  /// Directories searched for `name.ngc` when `o<name> call` names no sub defined so far.
  std::vector<std::string> subroutine_path;
  /// Tools; shared, never modified by the interpreter (G10 L1 edits a private copy).
  std::shared_ptr<const tools::ToolTable> tool_table;
  /// Units of the tool table and of stored offsets/parameters (#5221.., #5161.., #54xx):
  /// LinuxCNC's machine units. The stand-alone `rs274` uses inches.
  canon::Units user_units = canon::Units::Inch;
  /// Length units at program start (before any G20/G21).
  canon::Units initial_units = canon::Units::Mm;
  Limits limits;
  /// The machine has a spindle. Without one (an EDM, a flame cutter) a feed move with the
  /// spindle stopped is the normal case, not a habit to point out.
  bool spindle = true;
  bool block_delete = false;   ///< skip blocks starting with '/'
  ToolChangePosition tool_change;  ///< where M6 moves first (none by default)
  bool optional_stop = true;   ///< M1 stops
  MainM99 main_m99 = MainM99::End;
  /// Drop all canonical output until the motion with this segment id (replay to segment k);
  /// the interpreter state evolves exactly as in a full run. 0 = drop nothing.
  canon::SegmentId quiet_until_segment = 0;
  /// Code handlers, compensator and transform of the modules built on the core (extension.hpp).
  std::shared_ptr<const Extensions> extensions;
};

}  // namespace opencnc::gcode
