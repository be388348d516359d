// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc scan`: a program's summary from a scan run (moves, length, extents, time, tools).
#pragma once

#include <string>

#include "commands.hpp"
#include "opencnc/config/machine_profile.hpp"
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

/// The least machining time a program can take: feed moves at their programmed feed, rapids at
/// the speed of all linear axes at their limits together, dwells. Per-revolution moves and
/// accelerations are not counted, so the machine can only take longer.
struct TimeEstimate {
  bool complete = false;  ///< the scan reached the program's end without an error
  double feed_s = 0, rapid_s = 0, dwell_s = 0;
  double slowest_move_s = 0;    ///< the feed move that takes longest
  std::string slowest_move_at;  ///< "file:line" of it
  double total_s() const { return feed_s + rapid_s + dwell_s; }
};

/// Scans `file` as `opencnc run` interprets it on `profile` (bounded memory, no output).
/// CLI thread.
TimeEstimate estimate_machining_time(const std::string& file, const config::MachineProfile& profile);

}  // namespace opencnc::cli
