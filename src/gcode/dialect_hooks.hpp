// SPDX-License-Identifier: GPL-3.0-or-later
// DialectHooks — the seam between the interpreter's core and a dialect: what the dialect does
// differently, chosen once when a program opens (the engine takes dialect_hooks(Options::dialect)
// in its constructor). The core never asks which dialect it runs; LinuxCNC's hooks are all empty.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>

#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/options.hpp"
#include "parser.hpp"

namespace opencnc::gcode {

class Engine;

/// A dialect's own state in the engine (its program index, the words it took out of a block).
class DialectState {
 public:
  virtual ~DialectState() = default;
};

/// A dialect's hooks, each null where the dialect reads and runs as the core does. Called from
/// the interpreter's thread, in the order of a line's way through the engine (docs/interpreter.md).
struct DialectHooks {
  std::string_view name = "LinuxCNC";  ///< for messages ("not Fanuc G-code")
  SyntaxRules syntax;                  ///< how its lines read (the parser's rules)
  /// Its G and M code modules, added to the standard ones (standard_extensions).
  void (*add_codes)(Extensions& ext) = nullptr;
  /// Its state, made with the engine (which it may set up: vacant variables, letters).
  std::unique_ptr<DialectState> (*make_state)(Engine& e) = nullptr;
  /// The program's start-up (a lathe's plane and feed mode).
  void (*start)(Engine& e) = nullptr;
  /// Whether a program's first line is the dialect's own header ("%O1000(NAME)": a tape opened
  /// and its program numbered on one line).
  bool (*program_header)(std::string_view line) = nullptr;
  /// A lone '%' line: true when the dialect took it (a subprogram file's opening line).
  bool (*percent_line)(Engine& e) = nullptr;
  /// A line that starts with '$' or '%': another controller's syntax named as such (always,
  /// before the line is read); null: the core's check for LinuxCNC's dialect.
  void (*foreign_syntax)(Engine& e) = nullptr;
  /// The block's words rewritten into the core's, before the checks (a lathe's U and W, G50 S).
  void (*translate)(Engine& e) = nullptr;
  /// The block's parameter assignments, instead of the core's (vacant variables, #3000 alarms).
  void (*assignments)(Engine& e) = nullptr;
  /// Statements the core has not (GOTO, WHILE … END, G65, block ranges) and its program lines.
  void (*control_flow)(Engine& e) = nullptr;
  /// After each block: `flow` when it was a control-flow statement.
  void (*block_done)(Engine& e, bool flow) = nullptr;
  /// The file ended (a subprogram without its return).
  void (*end_of_file)(Engine& e) = nullptr;
  /// An M code of the stop group the dialect's flow owns (M98 calls, M99 returns): true when taken.
  bool (*stop_code)(Engine& e, int m) = nullptr;
  /// A system variable the dialect computes (ParamHost::computed_variable).
  bool (*computed_variable)(Engine& e, int index, double& value) = nullptr;
  /// A call abandoned after an MDI error: its variables as before it (true when the dialect did).
  bool (*leave_call)(Engine& e, const CallFrame& f) = nullptr;
  /// The blocks N first .. N last of the running program read, not run (ExecContext::
  /// read_block_range; G71/G72 P Q).
  void (*read_block_range)(Engine& e, std::int64_t first, std::int64_t last, std::string_view what,
                           const std::function<void(const Block&)>& visit) = nullptr;
  /// On a lathe a tool change indexes the turret with the spindle turning (T0101).
  bool turret_keeps_spindle = false;
};

/// The hooks of `dialect`. Any thread.
const DialectHooks& dialect_hooks(Dialect dialect) noexcept;

}  // namespace opencnc::gcode
