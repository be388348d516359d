// SPDX-License-Identifier: GPL-3.0-or-later
// SIGINT and SIGTERM during a run: the first asks for a controlled stop, a second for an abort at
// once (the report is still written), a third quits at once.
#pragma once

#include <atomic>

namespace opencnc::cli {

/// While it lives, SIGINT (Ctrl-C), SIGTERM and SIGHUP stop a run the controlled way: the first sets
/// requested() to the signal's number, which the run polls (feed hold on the path, then abort,
/// then the report with the reason); a second aborts the run at once, braking on the path, and
/// the report is written all the same; a third removes the temporary files of the outputs and
/// ends the process at once with exit code 128 + signal, without the report. The destructor
/// restores the previous handlers. CLI thread; the handler itself is async-signal-safe (lock-free
/// atomics, write, unlink, _exit).
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// The signal that asked for the stop, 0 while none has. Any thread; real-time safe.
  static const std::atomic<int>& requested() noexcept;
  /// How many stop signals came. Any thread; real-time safe.
  static const std::atomic<int>& count() noexcept;
};

/// "SIGINT", "SIGTERM", "SIGHUP" (or "a signal"). Any thread.
const char* signal_name(int signal) noexcept;

}  // namespace opencnc::cli
