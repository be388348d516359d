// SPDX-License-Identifier: GPL-3.0-or-later
// Registers the interpreter modules: one line per module, in the order they take effect.
#include "opencnc/gcode/standard_extensions.hpp"

#include "dialect_hooks.hpp"
#include "opencnc/gcode/canned_cycles.hpp"
#include "opencnc/gcode/cutter_comp.hpp"
#include "opencnc/gcode/lathe_cycles.hpp"
#include "opencnc/gcode/probing.hpp"
#include "opencnc/gcode/splines.hpp"
#include "opencnc/gcode/threading.hpp"

namespace opencnc::gcode {

std::shared_ptr<const Extensions> standard_extensions(Dialect dialect) {
  auto ext = std::make_shared<Extensions>();
  add_cutter_compensation(*ext);
  add_canned_cycles(*ext);
  add_threading(*ext);
  add_probing(*ext);
  add_splines(*ext);
  add_lathe_cycles(*ext);
  if (const auto add = dialect_hooks(dialect).add_codes) add(*ext);  // the dialect's own
  return ext;
}

}  // namespace opencnc::gcode
