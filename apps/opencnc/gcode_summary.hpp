// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc scan`: a program's summary from a scan run (moves, length, extents, time, tools).
#pragma once

#include <string>

#include "commands.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::cli {

/// How `opencnc scan` prints.
struct ScanOutput {
  bool json = false;             ///< the summary as JSON
  double rapid_rate_mm_min = 0;  ///< > 0: rapids are timed at this rate
  bool progress = false;         ///< progress on stderr also when it is not a terminal
};

/// Scans `file` in bounded memory (every move is measured once, then dropped) and prints its
/// summary; returns the exit code. CLI thread.
int run_scan(const std::string& file, const gcode::Options& options, const ScanOutput& out);

}  // namespace opencnc::cli
