// SPDX-License-Identifier: GPL-3.0-or-later
// connect::ObservationBuffer — the agent's bounded, sequence-numbered history of value changes
// (MTConnect's buffer: firstSequence … lastSequence), with the current value of every data item
// and the state at any retained sequence.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace opencnc::connect {

/// A condition's level (the streams' element of a CONDITION observation).
enum class Level : std::uint8_t { Unavailable, Normal, Warning, Fault };

/// "Unavailable", "Normal", "Warning", "Fault". Any thread.
const char* to_string(Level l) noexcept;

/// One value change. For samples and events `value` is the text ("UNAVAILABLE" when unknown);
/// for conditions `level`, `native_code` (which condition of the item; "" on a Normal that clears
/// them all) and `value` (its message).
struct Observation {
  std::uint64_t sequence = 0;
  std::int64_t time_us = 0;  ///< microseconds since 1970-01-01 UTC
  std::uint32_t item = 0;    ///< index into DeviceModel::items()
  Level level = Level::Unavailable;
  std::string native_code;
  std::string value;
};

/// The state of one data item: its last observation, and for a condition every condition active
/// (each native code's last Warning or Fault; empty = Normal).
struct ItemState {
  Observation last;
  std::vector<Observation> active;
};

/// The buffer. Not thread-safe: the agent serialises access.
class ObservationBuffer {
 public:
  /// `items`: the model's data item count, each starting UNAVAILABLE; `capacity` ≥ 1.
  ObservationBuffer(std::size_t items, std::size_t capacity);

  /// Appends `o` (its sequence is assigned) and updates the current state; the oldest observation
  /// leaves when the buffer is full. Returns the sequence.
  std::uint64_t add(Observation o);

  std::uint64_t first_sequence() const noexcept { return first_; }
  std::uint64_t next_sequence() const noexcept { return next_; }
  /// The last sequence stored (first − 1 when empty).
  std::uint64_t last_sequence() const noexcept { return next_ - 1; }
  std::size_t capacity() const noexcept { return capacity_; }
  std::size_t size() const noexcept { return buffer_.size(); }

  /// The observation with this sequence (first ≤ sequence < next).
  const Observation& at(std::uint64_t sequence) const;
  /// Every item's state now.
  const std::vector<ItemState>& current() const noexcept { return current_; }
  /// Every item's state just after observation `sequence` (first − 1 ≤ sequence < next): the
  /// state before the oldest retained observation with the retained ones replayed up to it.
  std::vector<ItemState> state_at(std::uint64_t sequence) const;

 private:
  static void apply(std::vector<ItemState>& state, const Observation& o);

  std::size_t capacity_;
  std::uint64_t first_ = 1, next_ = 1;
  std::deque<Observation> buffer_;
  std::vector<ItemState> current_;
  std::vector<ItemState> before_first_;  ///< the state before buffer_.front()
};

}  // namespace opencnc::connect
