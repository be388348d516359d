// SPDX-License-Identifier: GPL-3.0-or-later
// SpscRing — a fixed-size single-producer/single-consumer ring of plain records, lock-free and
// without pointers, so that it can live in shared memory between the servo and the controller.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace opencnc::control {

/// A ring of N records of T (N a power of two). One producer thread pushes, one consumer thread
/// pops; both sides are real-time safe and never block. Counters are 64-bit and never wrap in
/// practice, so `pushed()` and `popped()` also number the records (the k-th record pushed has
/// number k), which lets a consumer skip records up to a fence (`drop_until`).
template <typename T, std::size_t N>
class SpscRing {
  static_assert((N & (N - 1)) == 0 && N > 0, "capacity must be a power of two");
  static_assert(std::is_trivially_copyable_v<T>, "records cross the real-time boundary as plain data");

 public:
  static constexpr std::size_t kCapacity = N;

  SpscRing() noexcept = default;
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  /// Appends a copy of `v`; false when full. Producer thread; real-time safe.
  bool try_push(const T& v) noexcept {
    const std::uint64_t h = head_.load(std::memory_order_relaxed);
    if (h - tail_.load(std::memory_order_acquire) >= N) return false;
    slots_[h & (N - 1)] = v;
    head_.store(h + 1, std::memory_order_release);
    return true;
  }
  /// Free slots. Producer thread; real-time safe.
  std::size_t free_slots() const noexcept {
    return N - static_cast<std::size_t>(head_.load(std::memory_order_relaxed) -
                                        tail_.load(std::memory_order_acquire));
  }
  /// Records ever pushed (the number the next record will get). Producer thread; real-time safe.
  std::uint64_t pushed() const noexcept { return head_.load(std::memory_order_relaxed); }

  /// Records published and not yet popped. Consumer thread; real-time safe.
  std::size_t available() const noexcept {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) -
                                    tail_.load(std::memory_order_relaxed));
  }
  /// The oldest unpopped record (available() > 0). Consumer thread; real-time safe.
  const T& front() const noexcept { return slots_[tail_.load(std::memory_order_relaxed) & (N - 1)]; }
  /// Takes the oldest record into `out`; false when empty. Consumer thread; real-time safe.
  bool try_pop(T& out) noexcept {
    const std::uint64_t t = tail_.load(std::memory_order_relaxed);
    if (head_.load(std::memory_order_acquire) == t) return false;
    out = slots_[t & (N - 1)];
    tail_.store(t + 1, std::memory_order_release);
    return true;
  }
  /// Discards the oldest record (available() > 0). Consumer thread; real-time safe.
  void pop() noexcept { tail_.store(tail_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }
  /// Discards every published record numbered below `fence`. Consumer thread; real-time safe.
  void drop_until(std::uint64_t fence) noexcept {
    const std::uint64_t t = tail_.load(std::memory_order_relaxed);
    const std::uint64_t h = head_.load(std::memory_order_acquire);
    const std::uint64_t to = fence < h ? fence : h;
    if (to > t) tail_.store(to, std::memory_order_release);
  }
  /// Records ever popped (the number of the oldest unpopped one). Either thread; real-time safe.
  std::uint64_t popped() const noexcept { return tail_.load(std::memory_order_acquire); }

 private:
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::atomic<std::uint64_t> tail_{0};
  alignas(64) std::array<T, N> slots_{};
};

}  // namespace opencnc::control
