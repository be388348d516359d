// SPDX-License-Identifier: GPL-3.0-or-later
// The broaching codes: M171-M175 switch the machine's axis coupling (a helix of constant or
// variable pitch, a pitch table, a cam) on and off from a program (docs/broaching.md).
#pragma once

#include <memory>

#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::gcode {

/// Registers M171 (constant pitch P), M172 (pitch P changing by Q per unit of master travel),
/// M173 (pitch table P), M174 (cam table P) and M175 (uncouple) in `ext`. Non-real-time.
void add_coupling_codes(Extensions& ext);

/// standard_extensions(dialect) with the coupling codes: what a machine with a [coupling]
/// section gives GcodeSourceConfig::extensions. Non-real-time; any thread.
std::shared_ptr<const Extensions> coupling_extensions(Dialect dialect);

}  // namespace opencnc::gcode
