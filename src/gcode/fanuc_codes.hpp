// SPDX-License-Identifier: GPL-3.0-or-later
// Registration of the Fanuc dialect's codes with the extension registry.
#pragma once

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

/// G50/G51 scaling, G50.1/G51.1 mirroring, G68/G69 rotation and the transform that applies
/// them (transforms.cpp).
void add_transform_codes(Extensions& ext);

/// The Fanuc lathe cycles of their own: G75 grooving and G76 threading (fanuc_lathe.cpp).
void add_fanuc_lathe_cycles(Extensions& ext);

/// Everything the Fanuc dialect adds: the transforms, M31 (parts counter) and the machine
/// builder's M codes (fanuc_codes.cpp).
void add_fanuc_codes(Extensions& ext);

}  // namespace opencnc::gcode
