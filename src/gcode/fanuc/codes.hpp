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

/// G71/G72 stock removal on the program's own blocks N P .. N Q (fanuc_roughing.cpp).
void add_fanuc_roughing_cycles(Extensions& ext);

/// A length word of a Fanuc cycle (G75/G76 P and Q, the one-block G71/G72 D): written
/// without a decimal point it counts least increments (0.001 mm, 0.0001 in). Interpreter thread.
double length_word(ExecContext& ctx, const Block& b, char letter);

/// Ends the block with `gcode.unsupported` unless the machine is a lathe (the Fanuc lathe
/// cycles' numbers are other cycles on a mill). Interpreter thread.
void require_lathe(ExecContext& ctx, int code);

/// Everything the Fanuc dialect adds: the transforms, M31 (parts counter) and the machine
/// builder's M codes (fanuc_codes.cpp).
void add_fanuc_codes(Extensions& ext);

}  // namespace opencnc::gcode
