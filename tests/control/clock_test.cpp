// SPDX-License-Identifier: GPL-3.0-or-later
// Clocks: the virtual clock is exact; the periodic thread ticks, stops, and records its latency.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "opencnc/control/clock.hpp"

using namespace opencnc::control;

namespace {
struct Counter final : Tickable {
  std::atomic<std::uint64_t> n{0};
  std::uint64_t stop_after = UINT64_MAX;
  bool tick() noexcept override { return ++n < stop_after; }
};
}  // namespace

TEST(VirtualClock, RunsExactlyTheRequestedTicks) {
  VirtualClock clock(1'000'000);
  Counter c;
  EXPECT_EQ(clock.run(c, 2500), 2500u);
  EXPECT_EQ(c.n, 2500u);
  EXPECT_EQ(clock.now_ns(), 2'500'000'000);
}

TEST(VirtualClock, StopsWhenTheTickAsks) {
  VirtualClock clock(500'000);
  Counter c;
  c.stop_after = 10;
  EXPECT_EQ(clock.run(c, 1000), 10u);
  EXPECT_EQ(clock.now_ns(), 5'000'000);
}

TEST(LatencyHistogram, BinsPercentilesAndMoments) {
  LatencyHistogram h;
  for (int i = 0; i < 90; ++i) h.record(2'500);     // 2 µs bin
  for (int i = 0; i < 10; ++i) h.record(40'000);    // 40 µs bin
  h.record(5'000'000);                               // overflow
  auto counts = h.counts();
  EXPECT_EQ(counts[2], 90u);
  EXPECT_EQ(counts[40], 10u);
  EXPECT_EQ(counts[LatencyHistogram::kBins], 1u);
  EXPECT_EQ(h.samples(), 101u);
  EXPECT_EQ(h.min_ns(), 2'500);
  EXPECT_EQ(h.max_ns(), 5'000'000);
  EXPECT_EQ(h.percentile_ns(0.5), 3'000);
  EXPECT_EQ(h.percentile_ns(0.95), 41'000);
  EXPECT_EQ(h.percentile_ns(1.0), 5'000'000);
  EXPECT_NEAR(h.mean_ns(), (90 * 2500.0 + 10 * 40000.0 + 5e6) / 101.0, 1e-6);
  EXPECT_GT(h.stddev_ns(), 0.0);
}

TEST(RealtimeClock, TicksPeriodicallyUntilTheTickStops) {
  RealtimeClock::Options o;
  o.period_ns = 200'000;  // 200 µs
  RealtimeClock clock(o);
  Counter c;
  c.stop_after = 50;
  ASSERT_TRUE(clock.start(c));
  clock.wait();
  EXPECT_EQ(c.n, 50u);
  EXPECT_EQ(clock.ticks(), 50u);
  EXPECT_EQ(clock.latency().samples(), 50u);
  EXPECT_FALSE(clock.running());
  // Without privileges the clock must say why it is not real-time, never fail silently.
  if (!clock.realtime()) {
    EXPECT_FALSE(clock.warnings().empty());
  }
}

TEST(RealtimeClock, StopEndsARunningThread) {
  RealtimeClock::Options o;
  o.period_ns = 100'000;
  o.lock_memory = false;
  RealtimeClock clock(o);
  Counter c;
  ASSERT_TRUE(clock.start(c));
  while (c.n < 5) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  clock.stop();
  EXPECT_FALSE(clock.running());
  const auto after = c.n.load();
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(c.n.load(), after);
}

namespace {
// Ticks until `stop_after`; the tick numbered `slow` takes `slow_ns` of wall time.
struct SlowTick final : Tickable {
  std::uint64_t n = 0, stop_after = 10, slow = 3;
  std::int64_t slow_ns = 3'000'000;
  bool tick() noexcept override {
    if (++n == slow) std::this_thread::sleep_for(std::chrono::nanoseconds(slow_ns));
    return n < stop_after;
  }
};
}  // namespace

// A tick that outlasts two periods is an overrun whatever the machine; the log says the time went
// into the tick, not into a late wake-up, and names the periodic thread so benches can read its
// scheduler accounting.
TEST(RealtimeClock, LogsEachOverrunWithWhereItsTimeWent) {
  RealtimeClock::Options o;
  o.period_ns = 1'000'000;
  o.lock_memory = false;
  RealtimeClock clock(o);
  SlowTick t;
  ASSERT_TRUE(clock.start(t));
  clock.wait();
  ASSERT_GE(clock.overruns(), 1u);
  const auto log = clock.overrun_log();
  ASSERT_EQ(log.size(), clock.overruns());
  const bool found = std::any_of(log.begin(), log.end(), [](const OverrunRecord& r) {
    return r.done_ns - r.woke_ns >= 3'000'000 && r.woke_ns >= r.deadline_ns;
  });
  EXPECT_TRUE(found);
  EXPECT_GT(clock.thread_id(), 0);
}
