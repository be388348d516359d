// SPDX-License-Identifier: GPL-3.0-or-later
// BlockQueue: ring semantics, capacity, and one producer thread against one consumer thread.
#include <gtest/gtest.h>

#include <memory>
#include <thread>

#include "opencnc/traj/block_queue.hpp"

using namespace opencnc::traj;

TEST(BlockQueue, PushPeekPopInOrderUntilFull) {
  auto q = std::make_unique<BlockQueue>();
  EXPECT_EQ(q->available(), 0u);
  EXPECT_EQ(q->free_slots(), BlockQueue::kCapacity);
  for (std::uint64_t i = 0; i < BlockQueue::kCapacity; ++i) {
    MotionBlock b;
    b.seq = i;
    ASSERT_TRUE(q->try_push(b));
  }
  MotionBlock extra;
  EXPECT_FALSE(q->try_push(extra));
  EXPECT_EQ(q->available(), BlockQueue::kCapacity);
  EXPECT_EQ(q->peek(0).seq, 0u);
  EXPECT_EQ(q->peek(BlockQueue::kCapacity - 1).seq, BlockQueue::kCapacity - 1);
  q->pop(10);
  EXPECT_EQ(q->popped(), 10u);
  EXPECT_EQ(q->peek(0).seq, 10u);
  EXPECT_EQ(q->free_slots(), 10u);
  MotionBlock b;
  b.seq = 77;
  ASSERT_TRUE(q->try_push(b));  // wraps around into slot 0
  EXPECT_EQ(q->peek(q->available() - 1).seq, 77u);
  q->reset();
  EXPECT_EQ(q->available(), 0u);
  EXPECT_EQ(q->pushed(), 0u);
}

TEST(BlockQueue, ProducerAndConsumerThreadsSeeEveryBlockOnce) {
  auto q = std::make_unique<BlockQueue>();
  constexpr std::uint64_t kBlocks = 200000;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kBlocks;) {
      MotionBlock b;
      b.seq = i;
      b.length = static_cast<double>(i);
      if (q->try_push(b)) ++i;
    }
  });
  std::uint64_t next = 0;
  bool ordered = true;
  while (next < kBlocks) {
    const std::size_t n = q->available();
    for (std::size_t i = 0; i < n; ++i) {
      const MotionBlock& b = q->peek(i);
      ordered = ordered && b.seq == next + i && b.length == static_cast<double>(next + i);
    }
    q->pop(n);
    next += n;
  }
  producer.join();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(q->popped(), kBlocks);
}
