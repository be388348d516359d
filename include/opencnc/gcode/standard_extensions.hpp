// SPDX-License-Identifier: GPL-3.0-or-later
// The set of interpreter modules a complete controller uses, assembled in one place.
#pragma once

#include <memory>

#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::gcode {

/// Every module built on the interpreter core (cutter compensation, canned cycles, threading,
/// probing, splines, lathe cycles, the Fanuc dialect's codes and transforms), registered for
/// `dialect`. Front ends (CLI, controller, tests) pass this as Options::extensions. Each module
/// adds itself in standard_extensions.cpp. Non-real-time; cheap enough to call per run.
std::shared_ptr<const Extensions> standard_extensions(Dialect dialect);

}  // namespace opencnc::gcode
