// SPDX-License-Identifier: GPL-3.0-or-later
// BlockQueue — the single-producer/single-consumer ring of motion blocks from the planner to the
// tick. Fixed size, no pointers, lock-free: it can be placed in shared memory.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "opencnc/traj/motion_block.hpp"

namespace opencnc::traj {

/// A ring of kCapacity blocks. One producer (the planner) pushes, one consumer (the tick) reads
/// ahead and pops. Indices are 64-bit counters that never wrap in practice. Standard layout with
/// lock-free atomics only, so an instance may be constructed in shared memory.
class BlockQueue {
 public:
  static constexpr std::size_t kCapacity = 4096;
  static_assert((kCapacity & (kCapacity - 1)) == 0, "capacity must be a power of two");

  BlockQueue() noexcept = default;
  BlockQueue(const BlockQueue&) = delete;
  BlockQueue& operator=(const BlockQueue&) = delete;

  // --- producer side --------------------------------------------------------------------
  /// Free slots. Producer thread; real-time safe.
  std::size_t free_slots() const noexcept {
    return kCapacity - static_cast<std::size_t>(head_.load(std::memory_order_relaxed) -
                                                tail_.load(std::memory_order_acquire));
  }
  /// Appends a copy of `b`; false when full. Producer thread; real-time safe.
  bool try_push(const MotionBlock& b) noexcept {
    if (free_slots() == 0) return false;
    next_slot() = b;
    commit();
    return true;
  }
  /// The slot the next block goes into, to be written in place and then published with
  /// commit(); only while free_slots() > 0. Saves a copy of the 408-byte record. Producer
  /// thread; real-time safe.
  MotionBlock& next_slot() noexcept {
    return slots_[head_.load(std::memory_order_relaxed) & (kCapacity - 1)];
  }
  /// Publishes the block written into next_slot(). Producer thread; real-time safe.
  void commit() noexcept {
    head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }
  /// Number of blocks ever pushed. Producer thread; real-time safe.
  std::uint64_t pushed() const noexcept { return head_.load(std::memory_order_relaxed); }

  // --- consumer side --------------------------------------------------------------------
  /// Blocks published and not yet popped. Consumer thread; real-time safe.
  std::size_t available() const noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) -
                                    tail_.load(std::memory_order_relaxed));
  }
  /// The i-th unpopped block (i < available()). Consumer thread; real-time safe.
  const MotionBlock& peek(std::size_t i) const noexcept {
    return slots_[(tail_.load(std::memory_order_relaxed) + i) & (kCapacity - 1)];
  }
  /// Releases the n oldest blocks (n ≤ available()). Consumer thread; real-time safe.
  void pop(std::size_t n) noexcept {
    tail_.store(tail_.load(std::memory_order_relaxed) + n, std::memory_order_release);
  }
  /// Number of blocks ever popped. Either thread; real-time safe.
  std::uint64_t popped() const noexcept { return tail_.load(std::memory_order_acquire); }

  /// Empties the ring. Only while neither side is running (e.g. between programs).
  void reset() noexcept {
    head_.store(0, std::memory_order_relaxed);
    tail_.store(0, std::memory_order_relaxed);
  }

 private:
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::atomic<std::uint64_t> tail_{0};
  alignas(64) std::array<MotionBlock, kCapacity> slots_{};
};

static_assert(std::atomic<std::uint64_t>::is_always_lock_free);
static_assert(std::is_standard_layout_v<BlockQueue>);

}  // namespace opencnc::traj
