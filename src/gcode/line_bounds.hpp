// SPDX-License-Identifier: GPL-3.0-or-later
// LineBounds — the counts that end a runaway program (Options::limits): blocks executed, lines
// passed over while seeking a label, the scan's CPU time (line_bounds.cpp).
#pragma once

#include <cstdint>

#include "opencnc/gcode/options.hpp"

namespace opencnc::gcode {

/// Counts one engine's lines against its limits. Interpreter thread.
class LineBounds {
 public:
  /// A line was read: `skipping` while a label is sought (counted as passed over), else a
  /// block to execute (counted in `blocks_executed`). Throws GcodeError (gcode.limit-*) when a
  /// bound is passed. Inline: it runs on every line, and the common case is a few compares.
  void count(const Options& opt, bool skipping, std::uint64_t& blocks_executed) {
    const Limits& l = opt.limits;
    // The clock is read every 4096 lines only: a call per line would cost more than the line.
    if (l.max_seconds > 0 && opt.mode == Mode::Scan && (lines_read_++ & 4095) == 0)
      check_time(l.max_seconds, blocks_executed);
    if (skipping) {
      if (l.max_skipped_lines != 0 && ++skipped_lines_ > l.max_skipped_lines)
        too_many_skipped(l.max_skipped_lines);
    } else if (l.max_blocks != 0 && ++blocks_executed > l.max_blocks) {
      too_many_blocks(l.max_blocks);
    }
  }
  /// The main program starts again (M99 repeat): its lines passed over count afresh.
  void restart() noexcept { skipped_lines_ = 0; }

 private:
  void check_time(double max_seconds, std::uint64_t blocks_executed);
  [[noreturn]] static void too_many_skipped(std::uint64_t limit);
  [[noreturn]] static void too_many_blocks(std::uint64_t limit);

  std::uint64_t lines_read_ = 0;     ///< every line, for the time bound
  std::uint64_t skipped_lines_ = 0;  ///< lines passed over while seeking a label
  double cpu_at_start_s_ = 0;        ///< the thread's CPU time at the first line
};

}  // namespace opencnc::gcode
