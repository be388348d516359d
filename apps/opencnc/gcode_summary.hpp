// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc scan`: a program's summary from a scan run (moves, length, extents, time, tools).
#pragma once

#include <string>

#include "commands.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::cli {

/// Scans `file` and prints its summary (text or JSON); returns the exit code.
int run_scan(const std::string& file, const gcode::Options& options, bool json, double rapid_rate_mm_min);

}  // namespace opencnc::cli
