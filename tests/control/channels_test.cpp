// SPDX-License-Identifier: GPL-3.0-or-later
// The lock-free channels between servo and controller: order, capacity, fences, and two threads
// hammering a ring and a triple buffer (no lost, duplicated or torn records).
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "opencnc/control/channels.hpp"

namespace opencnc::control {
namespace {

TEST(SpscRing, KeepsOrderAndCapacity) {
  SpscRing<int, 4> r;
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(r.try_push(i));
  EXPECT_FALSE(r.try_push(99));
  EXPECT_EQ(r.available(), 4u);
  int v = -1;
  ASSERT_TRUE(r.try_pop(v));
  EXPECT_EQ(v, 0);
  EXPECT_EQ(r.front(), 1);
  EXPECT_TRUE(r.try_push(4));
  for (int want = 1; want <= 4; ++want) {
    ASSERT_TRUE(r.try_pop(v));
    EXPECT_EQ(v, want);
  }
  EXPECT_FALSE(r.try_pop(v));
  EXPECT_EQ(r.pushed(), 5u);
  EXPECT_EQ(r.popped(), 5u);
}

TEST(SpscRing, DropUntilSkipsStaleRecordsOnly) {
  SpscRing<int, 8> r;
  for (int i = 0; i < 6; ++i) r.try_push(i);
  r.drop_until(4);  // records 0..3 belong to an old run
  int v = -1;
  ASSERT_TRUE(r.try_pop(v));
  EXPECT_EQ(v, 4);
  r.drop_until(2);  // a fence behind the reader changes nothing
  ASSERT_TRUE(r.try_pop(v));
  EXPECT_EQ(v, 5);
  r.drop_until(100);  // beyond what was pushed: stops at the end
  EXPECT_EQ(r.popped(), 6u);
  r.try_push(6);
  ASSERT_TRUE(r.try_pop(v));
  EXPECT_EQ(v, 6);
}

TEST(SpscRing, TwoThreadsLoseNothing) {
  auto r = std::make_unique<SpscRing<std::uint64_t, 64>>();
  constexpr std::uint64_t kCount = 50000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kCount;) {
      if (r->try_push(i * 2654435761u)) ++i;
    }
  });
  std::uint64_t expected = 0, bad = 0, v = 0;
  while (expected < kCount) {
    if (!r->try_pop(v)) continue;
    bad += v != expected * 2654435761u;
    ++expected;
  }
  producer.join();
  EXPECT_EQ(bad, 0u);
}

struct Snapshot {
  std::uint64_t n = 0;
  std::array<std::uint64_t, 64> copies{};  // all equal to n when not torn
};

TEST(TripleBuffer, ReaderSeesOnlyWholeAndNewerValues) {
  auto b = std::make_unique<TripleBuffer<Snapshot>>();
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t n = 1; n <= 100000; ++n) {
      Snapshot& s = b->back();
      s.n = n;
      s.copies.fill(n);
      b->publish();
    }
    done = true;
  });
  std::uint64_t last = 0, torn = 0, backwards = 0, updates = 0;
  for (;;) {
    const bool finished = done.load();
    if (!b->update()) {
      if (finished) break;
      continue;
    }
    ++updates;
    const Snapshot& s = b->front();
    for (std::uint64_t c : s.copies) torn += c != s.n;
    backwards += s.n <= last;
    last = s.n;
  }
  writer.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_GT(updates, 0u);
  EXPECT_EQ(b->front().n, 100000u);  // the newest value is never lost
}

TEST(ServoChannels, ArePlainSharedMemoryData) {
  EXPECT_TRUE(std::is_standard_layout_v<ServoChannels>);
  EXPECT_TRUE(std::is_trivially_copyable_v<Command>);
  EXPECT_TRUE(std::is_trivially_copyable_v<ServoStatus>);
  EXPECT_TRUE(std::is_trivially_copyable_v<TraceSample>);
}

}  // namespace
}  // namespace opencnc::control
