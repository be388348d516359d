// SPDX-License-Identifier: GPL-3.0-or-later
// Clocks that drive the servo tick: virtual time (tests, simulation) and a real-time periodic thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/control/tickable.hpp"

namespace opencnc::control {

/// Runs ticks back to back in virtual time: deterministic, as fast as the CPU allows.
/// Any single thread; not real-time itself (it is the test and simulation driver).
class VirtualClock {
 public:
  explicit VirtualClock(std::int64_t period_ns) : period_ns_(period_ns) {}
  /// Ticks until `t` returns false or `max_ticks` have run; returns the number of ticks run.
  std::uint64_t run(Tickable& t, std::uint64_t max_ticks);
  std::int64_t period_ns() const noexcept { return period_ns_; }
  /// Virtual time elapsed since construction.
  std::int64_t now_ns() const noexcept { return now_ns_; }

 private:
  std::int64_t period_ns_;
  std::int64_t now_ns_ = 0;
};

/// Wake-up latency histogram of a periodic thread, in 1 µs bins; written by the periodic thread
/// (lock-free, relaxed atomics), read by anyone.
class LatencyHistogram {
 public:
  static constexpr int kBins = 1000;  ///< 0..999 µs; later wake-ups land in the overflow bin

  /// Records one wake-up `late_ns` after its deadline. Periodic thread; real-time safe.
  void record(std::int64_t late_ns) noexcept;
  /// Snapshot of the counts (bin i = [i, i+1) µs, last element = overflow). Any thread.
  std::vector<std::uint64_t> counts() const;
  std::uint64_t samples() const noexcept { return samples_.load(std::memory_order_relaxed); }
  std::int64_t max_ns() const noexcept { return max_ns_.load(std::memory_order_relaxed); }
  std::int64_t min_ns() const noexcept { return min_ns_.load(std::memory_order_relaxed); }
  /// Mean and standard deviation of the recorded latencies in ns. Any thread.
  double mean_ns() const noexcept;
  double stddev_ns() const noexcept;
  /// Smallest latency below which `fraction` of the samples lie, in ns (bin resolution). Any thread.
  std::int64_t percentile_ns(double fraction) const;

 private:
  std::atomic<std::uint64_t> bins_[kBins + 1] = {};
  std::atomic<std::uint64_t> samples_{0};
  std::atomic<std::int64_t> max_ns_{0};
  std::atomic<std::int64_t> min_ns_{INT64_MAX};
  std::atomic<double> sum_ns_{0};
  std::atomic<double> sum_sq_ns2_{0};
};

/// One overrun as the periodic thread saw it, in CLOCK_MONOTONIC ns: whether the thread woke late
/// (`woke_ns - deadline_ns`) or its tick ran long (`done_ns - woke_ns`) tells where the time went.
struct OverrunRecord {
  std::int64_t deadline_ns = 0;
  std::int64_t woke_ns = 0;
  std::int64_t done_ns = 0;
};

/// A periodic thread with absolute-time sleeps (clock_nanosleep on CLOCK_MONOTONIC), SCHED_FIFO and
/// mlockall where permitted (a clear warning and a normal thread where not), overrun counting and a
/// wake-up latency histogram. Start/stop from a non-real-time thread.
class RealtimeClock {
 public:
  struct Options {
    std::int64_t period_ns = 1'000'000;
    int priority = 80;          ///< SCHED_FIFO priority (1..99)
    int cpu = -1;               ///< pin to this CPU, -1 = no pinning
    bool lock_memory = true;    ///< mlockall(MCL_CURRENT | MCL_FUTURE)
  };

  explicit RealtimeClock(Options options);
  ~RealtimeClock();
  RealtimeClock(const RealtimeClock&) = delete;
  RealtimeClock& operator=(const RealtimeClock&) = delete;

  /// Starts calling `t.tick()` every period until stop() or until tick returns false.
  /// Returns false (with warnings()) only if no thread could be started at all.
  bool start(Tickable& t);
  /// Asks the thread to finish and joins it. Idempotent.
  void stop();
  /// Blocks until the thread ends by itself (tick returned false).
  void wait();
  bool running() const noexcept;

  /// Real-time scheduling obtained (false: fell back to a normal thread).
  bool realtime() const noexcept { return realtime_; }
  bool memory_locked() const noexcept { return memory_locked_; }
  /// Human-readable warnings from start(): why SCHED_FIFO or mlockall were not available.
  const std::vector<std::string>& warnings() const noexcept { return warnings_; }
  /// Periods whose tick finished after the next deadline.
  std::uint64_t overruns() const noexcept { return overruns_.load(std::memory_order_relaxed); }
  std::uint64_t ticks() const noexcept { return ticks_.load(std::memory_order_relaxed); }
  const LatencyHistogram& latency() const noexcept { return latency_; }
  /// The first kOverrunLog overruns, oldest first (fewer if fewer happened). Any thread.
  static constexpr std::size_t kOverrunLog = 512;
  std::vector<OverrunRecord> overrun_log() const;
  /// The periodic thread's kernel thread id (0 before it runs), so that a benchmark can read its
  /// scheduler accounting (/proc/self/task/<tid>/schedstat). Any thread.
  int thread_id() const noexcept { return thread_id_.load(std::memory_order_acquire); }

 private:
  struct Thread;
  void loop(Tickable& t) noexcept;

  Options options_;
  std::unique_ptr<Thread> thread_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::atomic<std::uint64_t> overruns_{0};
  std::atomic<std::uint64_t> ticks_{0};
  std::atomic<int> thread_id_{0};
  LatencyHistogram latency_;
  // Written by the periodic thread only, each slot before overruns_ is released past it.
  std::array<OverrunRecord, kOverrunLog> overrun_log_{};
  bool realtime_ = false;
  bool memory_locked_ = false;
  std::vector<std::string> warnings_;
};

}  // namespace opencnc::control
