// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, process alarms: the profile's analog process inputs (dielectric level and temperature, a
// resistor box's temperature) checked against their bounds every period, with hysteresis, and
// the alarm's reaction: a message, a feed hold of the running program, or a stop with a fault.
#include "opencnc/control/servo.hpp"

namespace opencnc::control {

using machine::AlarmReaction;

void Servo::check_process_alarms() noexcept {
  const machine::ProcessAlarms& alarms = config_.alarms;
  bool blocks = false;
  for (int i = 0; i < alarms.count && i < machine::kMaxProcessAlarms; ++i) {
    const machine::ProcessAlarm& a = alarms.alarms[static_cast<std::size_t>(i)];
    if (a.channel < 0 || a.channel >= machine::kAnalogChannels) continue;
    const double v = in_.analog_in[static_cast<std::size_t>(a.channel)];
    const std::uint16_t bit = static_cast<std::uint16_t>(1u << i);
    const bool active = (alarms_active_ & bit) != 0;
    // Out of range trips it; it clears only back inside by the hysteresis (a level that hovers at
    // a bound does not chatter). A NaN reading is out of range.
    const bool low = a.has_low && !(v >= a.low + (active ? a.hysteresis : 0.0));
    const bool high = a.has_high && !(v <= a.high - (active ? a.hysteresis : 0.0));
    if ((low || high) && !active) {
      alarms_active_ |= bit;
      trip_process_alarm(i, v, low);
    } else if (!low && !high && active) {
      alarms_active_ &= static_cast<std::uint16_t>(~bit);
      ServoEvent e;
      e.kind = EventKind::ProcessAlarmCleared;
      e.action = static_cast<std::uint32_t>(i);
      e.value = v;
      emit(e);
    }
    if ((alarms_active_ & bit) == 0) continue;
    if (a.reaction == AlarmReaction::FeedHold) blocks = true;
    // A stop alarm holds like a fault that persists: the machine cannot be on while it is out of
    // range (switched on again, it faults again).
    const bool on = state_ == State::Idle || state_ == State::Running || state_ == State::Held ||
                    state_ == State::Stopped;
    if (a.reaction == AlarmReaction::Stop && on)
      enter_fault({FaultKind::ProcessAlarm, static_cast<std::int8_t>(i), v, low ? a.low : a.high, tick_});
  }
  alarm_blocks_motion_ = blocks;
}

void Servo::trip_process_alarm(int index, double value, bool low) noexcept {
  const machine::ProcessAlarm& a = config_.alarms.alarms[static_cast<std::size_t>(index)];
  ServoEvent e;
  e.kind = EventKind::ProcessAlarm;
  e.action = static_cast<std::uint32_t>(index);
  e.value = value;
  e.axis = low ? 0 : 1;
  emit(e);
  switch (a.reaction) {
    case AlarmReaction::Message:
      return;
    case AlarmReaction::FeedHold:
      // As the operator's feed hold: a stop on the path, the program kept (jogs and homing are
      // the operator's own motion: they go on).
      if (activity_ == Activity::Program && !aborting_ && state_ == State::Running) {
        hold_ = true;
        set_state(State::Held);
      }
      return;
    case AlarmReaction::Stop:  // the fault follows in check_process_alarms
      return;
  }
}

}  // namespace opencnc::control
