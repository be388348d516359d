// SPDX-License-Identifier: GPL-3.0-or-later
// Process-input alarms as plain data: analog inputs (dielectric level and temperature, a resistor
// box's temperature) with thresholds, hysteresis and a reaction, which the servo tick evaluates.
#pragma once

#include <array>
#include <cstdint>

namespace opencnc::machine {

/// What the tick does when an input leaves its range.
enum class AlarmReaction : std::uint8_t {
  Message,   ///< a warning in the event log; nothing stops
  FeedHold,  ///< a running program is held on its path (cycle start is refused while out of range)
  Stop,      ///< the machine stops and faults (the drives off; reset refused while out of range)
};

/// One alarm: analog input `channel` must stay within [low, high] (either bound optional). Out of
/// range it trips; it clears once the value is back inside by `hysteresis`.
struct ProcessAlarm {
  int channel = -1;
  bool has_low = false, has_high = false;
  double low = 0, high = 0;
  double hysteresis = 0;
  AlarmReaction reaction = AlarmReaction::Message;
};

/// Most alarms a profile has (one bit each in the status).
inline constexpr int kMaxProcessAlarms = 16;

/// The profile's alarms, in profile order. Trivially copyable (lives in the servo's config).
struct ProcessAlarms {
  int count = 0;
  std::array<ProcessAlarm, kMaxProcessAlarms> alarms{};
};

}  // namespace opencnc::machine
