// SPDX-License-Identifier: GPL-3.0-or-later
// TripleBuffer — the latest value from one writer to one reader, wait-free on both sides and
// without pointers: how the servo publishes its status snapshot every period.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

namespace opencnc::control {

/// Three slots: the writer owns one, the reader owns one, the third is the hand-over. The
/// writer fills its slot and swaps it with the hand-over slot, marking it fresh; the reader
/// swaps its slot with the hand-over slot when that is fresh. Neither side ever waits or sees
/// a half-written value, and no copy is made under a lock (unlike a seqlock, the reader never
/// retries). Standard layout with a lock-free atomic, so it may live in shared memory.
template <typename T>
class TripleBuffer {
  static_assert(std::is_trivially_copyable_v<T>, "snapshots cross the real-time boundary as plain data");

 public:
  TripleBuffer() noexcept = default;
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  /// The writer's slot, to fill in place. Writer thread; real-time safe.
  T& back() noexcept { return slots_[back_]; }
  /// Publishes the writer's slot. Writer thread; real-time safe.
  void publish() noexcept {
    const std::uint8_t old =
        middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = static_cast<std::uint8_t>(old & kIndex);
  }
  /// Copies `v` into the writer's slot and publishes it. Writer thread; real-time safe.
  void write(const T& v) noexcept {
    back() = v;
    publish();
  }

  /// Takes the newest published value if there is a new one; returns whether it did. Reader
  /// thread; real-time safe.
  bool update() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return false;
    const std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = static_cast<std::uint8_t>(old & kIndex);
    return true;
  }
  /// The reader's current value (the newest after update()). Reader thread; real-time safe.
  const T& front() const noexcept { return slots_[front_]; }

 private:
  static constexpr std::uint8_t kIndex = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;

  alignas(64) std::atomic<std::uint8_t> middle_{1};
  alignas(64) std::uint8_t back_ = 0;   // writer side only
  alignas(64) std::uint8_t front_ = 2;  // reader side only
  alignas(64) std::array<T, 3> slots_{};
};

static_assert(std::atomic<std::uint8_t>::is_always_lock_free);

}  // namespace opencnc::control
