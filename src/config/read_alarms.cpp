// SPDX-License-Identifier: GPL-3.0-or-later
// Reading [alarms.<name>]: analog process inputs (dielectric level, dielectric and resistor-box
// temperature) with low/high bounds, hysteresis and a reaction, compiled into plain data.
#include <fmt/format.h>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

void read_alarm(Section& s, const std::string& name, MachineProfile& profile) {
  machine::ProcessAlarm a;
  if (const auto ch = s.integer("input", 0, machine::kAnalogChannels - 1)) {
    a.channel = static_cast<int>(*ch);
    if (a.channel >= profile.io.analog_inputs)
      s.error("input",
              fmt::format("{}.input ({}) is not an analog input of this machine ([io] analog_inputs = {})",
                          s.path(), a.channel, profile.io.analog_inputs),
              "config.range");
  } else if (!s.has("input")) {
    s.missing("input");
  }
  if (const auto v = s.number("low")) {
    a.has_low = true;
    a.low = *v;
  }
  if (const auto v = s.number("high")) {
    a.has_high = true;
    a.high = *v;
  }
  if (!s.has("low") && !s.has("high"))
    s.error("input", fmt::format("{} needs low, high or both", s.path()), "config.missing-key");
  a.hysteresis = s.number_or("hysteresis", 0, Bound::NonNegative);
  if (a.has_low && a.has_high && a.high - a.low <= 2 * a.hysteresis)
    s.error("high",
            fmt::format("{}: high ({}) must be more than low ({}) plus twice the hysteresis ({})", s.path(),
                        show(a.high), show(a.low), show(a.hysteresis)),
            "config.range");
  a.reaction = s.choice("reaction",
                        {{"message", machine::AlarmReaction::Message},
                         {"feed-hold", machine::AlarmReaction::FeedHold},
                         {"stop", machine::AlarmReaction::Stop}},
                        machine::AlarmReaction::Message);
  if (!s.has("reaction")) s.missing("reaction");
  AlarmProfile& out = profile.alarms;
  out.names.push_back(name);
  out.units.push_back(s.string("unit").value_or(""));
  if (a.channel >= 0) out.sim_values[static_cast<std::size_t>(a.channel)] = s.number_or("sim", 0);
  out.alarms.alarms[static_cast<std::size_t>(out.alarms.count++)] = a;
}

}  // namespace

void read_alarms(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("alarms");
  if (t == nullptr) return;
  for (const auto& [key, node] : *t) {
    const std::string name(key.str());
    const toml::table* at = node.as_table();
    if (at == nullptr) {
      top.error("alarms", fmt::format("alarms.{} must be a table ([alarms.{}])", name, name), "config.type");
      continue;
    }
    Section s(*at, "alarms." + name, {"input", "low", "high", "hysteresis", "reaction", "unit", "sim"},
              top.reporter());
    if (profile.alarms.alarms.count >= machine::kMaxProcessAlarms) {
      s.error("input", fmt::format("more than {} alarms", machine::kMaxProcessAlarms), "config.range");
      return;
    }
    read_alarm(s, name, profile);
  }
}

}  // namespace opencnc::config::detail
