// SPDX-License-Identifier: GPL-3.0-or-later
// Progress of a long interpreter run (`check`, `canon`, `scan`) on stderr: where it is, how many
// blocks and moves so far, how long it has run.
#pragma once

#include <string>

#include "opencnc/canon/sink.hpp"
#include "opencnc/gcode/interpreter.hpp"

namespace opencnc::cli {

/// Shows how a run advances, at most four times a second and only once it has run for half a
/// second (short programs print nothing): on one rewritten line when stderr is a terminal, else
/// one line a second when asked (`--progress`, for logs). CLI thread.
class InterpreterProgress {
 public:
  /// `what` names the run ("scan part.ngc"). `forced`: also when stderr is not a terminal.
  InterpreterProgress(std::string what, bool forced);
  /// Runs `interp` to its end or an error through `sink`, as Interpreter::run does, showing
  /// progress on the way (block by block with Interpreter::step only when it is shown).
  gcode::RunStatus run(gcode::Interpreter& interp, canon::Sink& sink);

 private:
  void show(const gcode::Interpreter& interp, double elapsed_s);
  void clear();

  std::string what_;
  bool terminal_ = false;
  bool enabled_ = false;
  bool shown_ = false;
};

}  // namespace opencnc::cli
