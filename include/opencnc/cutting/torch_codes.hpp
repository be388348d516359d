// SPDX-License-Identifier: GPL-3.0-or-later
// The plasma torch's codes as a code module: M190 torch on (find the plate, pierce, cut height,
// height control), M191 torch off (retract), M192 hold the height, M193 let it go (docs/cutting.md).
#pragma once

#include <memory>

#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::gcode {

/// Adds M190–M193 to `ext`: each a canonical process_code call, M190/M191 one modal group and
/// M192/M193 another (a program resumed at segment k gets the torch and the hold in force there).
void add_torch_codes(Extensions& ext);

/// `base` (or the dialect's standard modules) with the torch's codes.
std::shared_ptr<const Extensions> torch_extensions(Dialect dialect,
                                                   std::shared_ptr<const Extensions> base = nullptr);

}  // namespace opencnc::gcode
