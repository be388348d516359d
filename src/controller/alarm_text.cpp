// SPDX-License-Identifier: GPL-3.0-or-later
// Process alarms in words for the event log and the fault text.
#include "alarm_text.hpp"

#include <fmt/format.h>

namespace opencnc::controller::detail {

std::string alarm_text(const config::AlarmProfile& alarms, std::size_t index, double value, bool low,
                       bool cleared) {
  if (index >= alarms.names.size() || static_cast<int>(index) >= alarms.alarms.count) return "process alarm";
  const machine::ProcessAlarm& a = alarms.alarms.alarms[index];
  const std::string unit = alarms.units[index].empty() ? "" : " " + alarms.units[index];
  if (cleared)
    return fmt::format("alarm {}: input {} is back in range ({:.2f}{})", alarms.names[index], a.channel,
                       value, unit);
  const char* what = a.reaction == machine::AlarmReaction::Stop       ? "the machine stopped"
                     : a.reaction == machine::AlarmReaction::FeedHold ? "feed hold"
                                                                      : "message only";
  return fmt::format("alarm {}: input {} reads {:.2f}{}, {} its {} bound of {:g}{}: {}", alarms.names[index],
                     a.channel, value, unit, low ? "below" : "above", low ? "low" : "high",
                     low ? a.low : a.high, unit, what);
}

}  // namespace opencnc::controller::detail
