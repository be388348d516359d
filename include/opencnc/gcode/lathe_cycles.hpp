// SPDX-License-Identifier: GPL-3.0-or-later
// The LinuxCNC lathe cycles G70, G71, G71.1, G71.2, G72, G72.1, G72.2 as interpreter extensions.
#pragma once

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

/// Registers the lathe cycles (profile in the subprogram named by Q, roughing by
/// lathe_roughing.hpp). Non-real-time; call while assembling the Extensions.
void add_lathe_cycles(Extensions& ext);

}  // namespace opencnc::gcode
