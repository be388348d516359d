// SPDX-License-Identifier: GPL-3.0-or-later
// The problem codes of the lathe roughing engine's errors, shared by LinuxCNC's G70-G72
// (lathe_cycles.cpp) and Fanuc's G71/G72 (fanuc_roughing.cpp).
#pragma once

#include "opencnc/gcode/error_codes.hpp"
#include "opencnc/gcode/lathe_roughing.hpp"

namespace opencnc::gcode {

/// The problem code of a roughing engine error. Any thread.
ErrorCode roughing_error_code(lathe::RoughingError::Kind kind) noexcept;

}  // namespace opencnc::gcode
