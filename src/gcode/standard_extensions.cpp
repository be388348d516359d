// SPDX-License-Identifier: GPL-3.0-or-later
// Registers the interpreter modules: one line per module, in the order they take effect.
#include "opencnc/gcode/standard_extensions.hpp"

namespace opencnc::gcode {

std::shared_ptr<const Extensions> standard_extensions(Dialect dialect) {
  auto ext = std::make_shared<Extensions>();
  (void)dialect;
  return ext;
}

}  // namespace opencnc::gcode
