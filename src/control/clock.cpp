// SPDX-License-Identifier: GPL-3.0-or-later
// Virtual clock, real-time periodic thread (SCHED_FIFO, mlockall, absolute sleeps), latency histogram.
#include "opencnc/control/clock.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <thread>

#include <fmt/format.h>

namespace opencnc::control {

// --- virtual clock ----------------------------------------------------------------------------

std::uint64_t VirtualClock::run(Tickable& t, std::uint64_t max_ticks) {
  std::uint64_t n = 0;
  while (n < max_ticks) {
    ++n;
    now_ns_ += period_ns_;
    if (!t.tick()) break;
  }
  return n;
}

// --- latency histogram ------------------------------------------------------------------------

void LatencyHistogram::record(std::int64_t late_ns) noexcept {
  if (late_ns < 0) late_ns = 0;
  const std::int64_t us = late_ns / 1000;
  const int bin = us >= kBins ? kBins : static_cast<int>(us);
  bins_[bin].fetch_add(1, std::memory_order_relaxed);
  samples_.fetch_add(1, std::memory_order_relaxed);
  std::int64_t prev = max_ns_.load(std::memory_order_relaxed);
  while (late_ns > prev && !max_ns_.compare_exchange_weak(prev, late_ns, std::memory_order_relaxed)) {
  }
  prev = min_ns_.load(std::memory_order_relaxed);
  while (late_ns < prev && !min_ns_.compare_exchange_weak(prev, late_ns, std::memory_order_relaxed)) {
  }
  const double d = static_cast<double>(late_ns);
  sum_ns_.fetch_add(d, std::memory_order_relaxed);
  sum_sq_ns2_.fetch_add(d * d, std::memory_order_relaxed);
}

std::vector<std::uint64_t> LatencyHistogram::counts() const {
  std::vector<std::uint64_t> out(kBins + 1);
  for (int i = 0; i <= kBins; ++i) out[static_cast<std::size_t>(i)] = bins_[i].load(std::memory_order_relaxed);
  return out;
}

double LatencyHistogram::mean_ns() const noexcept {
  const auto n = samples();
  return n == 0 ? 0.0 : sum_ns_.load(std::memory_order_relaxed) / static_cast<double>(n);
}

double LatencyHistogram::stddev_ns() const noexcept {
  const auto n = samples();
  if (n < 2) return 0.0;
  const double mean = mean_ns();
  const double var = sum_sq_ns2_.load(std::memory_order_relaxed) / static_cast<double>(n) - mean * mean;
  return var > 0 ? std::sqrt(var) : 0.0;
}

std::int64_t LatencyHistogram::percentile_ns(double fraction) const {
  const auto all = counts();
  std::uint64_t total = 0;
  for (auto c : all) total += c;
  if (total == 0) return 0;
  const auto target = static_cast<std::uint64_t>(std::ceil(fraction * static_cast<double>(total)));
  std::uint64_t seen = 0;
  for (int i = 0; i <= kBins; ++i) {
    seen += all[static_cast<std::size_t>(i)];
    if (seen >= target) return i == kBins ? max_ns() : static_cast<std::int64_t>(i + 1) * 1000;
  }
  return max_ns();
}

// --- real-time periodic thread ----------------------------------------------------------------

struct RealtimeClock::Thread {
  std::thread thread;
};

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

std::int64_t to_ns(const timespec& ts) { return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec; }

timespec from_ns(std::int64_t ns) {
  timespec ts;
  ts.tv_sec = static_cast<time_t>(ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(ns % kNsPerS);
  return ts;
}

std::int64_t monotonic_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return to_ns(ts);
}

// Touches a stack region once so the periodic thread never page-faults on its stack later.
void prefault_stack() {
  volatile char stack[64 * 1024];
  for (std::size_t i = 0; i < sizeof stack; i += 4096) stack[i] = 0;
}

}  // namespace

RealtimeClock::RealtimeClock(Options options) : options_(options) {}

RealtimeClock::~RealtimeClock() { stop(); }

bool RealtimeClock::running() const noexcept { return running_.load(std::memory_order_acquire); }

bool RealtimeClock::start(Tickable& t) {
  if (thread_) return false;
  warnings_.clear();
  if (options_.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      memory_locked_ = true;
    } else {
      warnings_.push_back(fmt::format(
          "mlockall failed ({}): memory is not locked, page faults may delay the servo thread; "
          "raise RLIMIT_MEMLOCK (ulimit -l) or run with CAP_IPC_LOCK",
          std::strerror(errno)));
    }
  }
  stop_requested_.store(false, std::memory_order_release);
  running_.store(true, std::memory_order_release);
  thread_ = std::make_unique<Thread>();
  thread_->thread = std::thread([this, &t] { loop(t); });

  sched_param param{};
  param.sched_priority = options_.priority;
  const int rc = pthread_setschedparam(thread_->thread.native_handle(), SCHED_FIFO, &param);
  if (rc == 0) {
    realtime_ = true;
  } else {
    warnings_.push_back(fmt::format(
        "SCHED_FIFO priority {} not permitted ({}): running the servo thread as a normal thread, "
        "expect more jitter; grant CAP_SYS_NICE or an rtprio limit (see /etc/security/limits.conf)",
        options_.priority, std::strerror(rc)));
  }
  if (options_.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(options_.cpu), &set);
    const int arc = pthread_setaffinity_np(thread_->thread.native_handle(), sizeof set, &set);
    if (arc != 0) warnings_.push_back(fmt::format("cannot pin the servo thread to CPU {} ({})", options_.cpu,
                                                  std::strerror(arc)));
  }
  return true;
}

void RealtimeClock::loop(Tickable& t) noexcept {
  prefault_stack();
  thread_id_.store(static_cast<int>(gettid()), std::memory_order_release);
  const std::int64_t period = options_.period_ns;
  std::int64_t deadline = monotonic_ns();
  while (!stop_requested_.load(std::memory_order_acquire)) {
    deadline += period;
    const timespec wake = from_ns(deadline);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr) == EINTR) {
    }
    const std::int64_t woke = monotonic_ns();
    latency_.record(woke - deadline);
    const bool go_on = t.tick();
    ticks_.fetch_add(1, std::memory_order_relaxed);
    const std::int64_t done = monotonic_ns();
    // A tick that ends after the next deadline is an overrun; skip the periods already missed so
    // the schedule stays on the absolute grid instead of bursting to catch up.
    if (done > deadline + period) {
      const std::int64_t missed = (done - deadline) / period;
      const std::uint64_t n = overruns_.load(std::memory_order_relaxed);
      if (n < kOverrunLog) overrun_log_[n] = OverrunRecord{deadline, woke, done};
      overruns_.store(n + 1, std::memory_order_release);
      deadline += (missed - 1) * period;
    }
    if (!go_on) break;
  }
  running_.store(false, std::memory_order_release);
}

std::vector<OverrunRecord> RealtimeClock::overrun_log() const {
  const std::uint64_t n = overruns_.load(std::memory_order_acquire);
  return {overrun_log_.begin(), overrun_log_.begin() + static_cast<std::ptrdiff_t>(std::min<std::uint64_t>(n, kOverrunLog))};
}

void RealtimeClock::stop() {
  if (!thread_) return;
  stop_requested_.store(true, std::memory_order_release);
  if (thread_->thread.joinable()) thread_->thread.join();
  thread_.reset();
}

void RealtimeClock::wait() {
  if (!thread_) return;
  if (thread_->thread.joinable()) thread_->thread.join();
  thread_.reset();
}

}  // namespace opencnc::control
