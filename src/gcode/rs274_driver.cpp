// SPDX-License-Identifier: GPL-3.0-or-later
// run_like_rs274: the interpreter with the resets rs274's driver adds around a program.
#include "opencnc/gcode/rs274_driver.hpp"

namespace opencnc::gcode {

RunStatus run_like_rs274(Interpreter& interp, canon::Rs274Printer& printer, const RunFunction& run) {
  if (interp.start(printer) == RunStatus::Error) return RunStatus::Error;
  // The driver's resets belong to no block: no N label.
  printer.begin_block(canon::BlockOrigin{});
  printer.on_reset();
  const RunStatus status = run ? run(interp, printer) : interp.run(printer);
  printer.begin_block(canon::BlockOrigin{});
  printer.on_reset();
  printer.on_reset();
  return status;
}

}  // namespace opencnc::gcode
