// SPDX-License-Identifier: GPL-3.0-or-later
// Where a real-time servo thread's lost periods went: samples the thread's scheduler accounting and
// its CPU's stolen time (a hypervisor running someone else) while a benchmark runs, then attributes
// each overrun the clock logged.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "opencnc/control/clock.hpp"

namespace opencnc::bench {

/// One sample of the servo thread and its CPU, CLOCK_MONOTONIC ns.
struct AccountingSample {
  std::int64_t t_ns = 0;
  std::uint64_t steal_ticks = 0;       ///< /proc/stat: time the hypervisor gave the CPU away (USER_HZ)
  std::uint64_t run_delay_ns = 0;      ///< /proc/<tid>/schedstat: time runnable but not running
  std::uint64_t involuntary = 0;       ///< /proc/<tid>/status: preempted by another task
  std::uint64_t voluntary = 0;         ///< /proc/<tid>/status: slept (its period's sleep, or a wait)
};

/// Why one overrun happened, as far as the samples around it tell.
struct OverrunCause {
  control::OverrunRecord record;
  std::uint64_t steal_ticks = 0;       ///< stolen time on the servo's CPU around the overrun
  std::uint64_t run_delay_ns = 0;      ///< the servo thread waited for its CPU around the overrun
  std::uint64_t involuntary = 0;       ///< the servo thread was preempted around the overrun
};

/// Samples every `interval_ns` on a thread of its own (started after the servo's, so it keeps off
/// the servo's CPU) until stop(). Non-real-time; for benchmarks.
class ServoAccounting {
 public:
  /// `cpu` is the servo's CPU (-1: the whole machine's stolen time).
  ServoAccounting(int servo_tid, int cpu, std::int64_t interval_ns);
  ~ServoAccounting();
  void stop();
  /// Empty if the files could not be read (not Linux, no schedstats), else why not.
  const std::string& error() const { return error_; }
  const std::vector<AccountingSample>& samples() const { return samples_; }
  /// Each logged overrun with what the samples from `before_ns` ahead of its deadline to
  /// `after_ns` past its end saw. Call after stop().
  std::vector<OverrunCause> attribute(const std::vector<control::OverrunRecord>& log, std::int64_t before_ns,
                                      std::int64_t after_ns) const;

 private:
  bool sample(AccountingSample& s) const;

  int tid_, cpu_;
  std::int64_t interval_ns_;
  std::string error_;
  std::vector<AccountingSample> samples_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace opencnc::bench
