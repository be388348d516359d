// SPDX-License-Identifier: GPL-3.0-or-later
// The dialects' hooks by name: LinuxCNC's (the core's own, all empty) and the Fanuc dialect's.
#include "dialect_hooks.hpp"

#include "fanuc/dialect.hpp"

namespace opencnc::gcode {

const DialectHooks& dialect_hooks(Dialect dialect) noexcept {
  static const DialectHooks linuxcnc;
  return dialect == Dialect::Fanuc ? fanuc_hooks() : linuxcnc;
}

}  // namespace opencnc::gcode
