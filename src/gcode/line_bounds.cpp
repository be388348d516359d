// SPDX-License-Identifier: GPL-3.0-or-later
// The runaway bounds' clock and their errors.
#include "line_bounds.hpp"

#include <ctime>

#include "gcode_error.hpp"

namespace opencnc::gcode {

namespace {

// The thread's CPU time, not the wall clock: a loaded machine does not make a program fail its check.
double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

void LineBounds::check_time(double max_seconds, std::uint64_t blocks_executed) {
  const double now = thread_cpu_s();
  if (lines_read_ == 1) {
    cpu_at_start_s_ = now;
    return;
  }
  if (now - cpu_at_start_s_ > max_seconds)
    fail(ErrorCode::LimitTime,
         "the program was still running here after {:g} s of checking ({} blocks; limit max_seconds): an "
         "endless "
         "loop?",
         max_seconds, blocks_executed);
}

void LineBounds::too_many_skipped(std::uint64_t limit) {
  fail(ErrorCode::LimitSkippedLines,
       "more than {} lines passed over while looking for a label (limit max_skipped_lines)", limit);
}

void LineBounds::too_many_blocks(std::uint64_t limit) {
  fail(ErrorCode::LimitBlocks, "more than {} blocks executed (limit max_blocks)", limit);
}

}  // namespace opencnc::gcode
