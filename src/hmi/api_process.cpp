// SPDX-License-Identifier: GPL-3.0-or-later
// The process side of the API's status: the power supply, the broach's load and its guard, the
// process-input alarms with their state, the EDM's live values (docs/api.md, "GET /api/v1/status").
#include <string>

#include "opencnc/control/load_guard.hpp"
#include "opencnc/hmi/api.hpp"

namespace opencnc::hmi {

namespace {

using nlohmann::json;

const char* reaction_name(machine::AlarmReaction r) {
  return r == machine::AlarmReaction::Stop       ? "stop"
         : r == machine::AlarmReaction::FeedHold ? "feed-hold"
                                                 : "message";
}

const char* gap_name(machine::GapState g) {
  static constexpr const char* names[] = {"open", "normal", "arc", "short"};
  return names[static_cast<std::size_t>(g)];
}

json alarms_json(const control::ServoStatus& s, const config::AlarmProfile& p) {
  json list = json::array();
  for (int k = 0; k < p.alarms.count; ++k) {
    const machine::ProcessAlarm& a = p.alarms.alarms[static_cast<std::size_t>(k)];
    const auto i = static_cast<std::size_t>(k);
    list.push_back({{"name", i < p.names.size() ? p.names[i] : std::string("alarm ") + std::to_string(k + 1)},
                    {"active", (s.alarms_active >> k & 1U) != 0},
                    {"value", s.alarm_values[i]},
                    {"reaction", reaction_name(a.reaction)},
                    {"low", a.has_low ? json(a.low) : json(nullptr)},
                    {"high", a.has_high ? json(a.high) : json(nullptr)},
                    {"unit", i < p.units.size() ? p.units[i] : std::string()}});
  }
  return list;
}

json edm_json(const control::ServoStatus& s, const machine::EdmConfig& c) {
  const control::EdmStatus& e = s.edm;
  const machine::EdmCondition* cond = e.condition != 0 ? c.find(e.condition) : nullptr;
  return {{"on", e.on},
          {"generator", e.generator},
          {"condition", e.condition},
          // The reference in force (adaptive control moves it), else the condition's.
          {"reference_v", e.servo_reference_v > 0 ? json(e.servo_reference_v)
                          : cond != nullptr       ? json(cond->servo_reference_v)
                                                  : json(nullptr)},
          {"gain_mm_s_per_v", e.gain_mm_s_per_v},
          {"jump_period_s", e.jump_period_s},
          {"jump_height_mm", e.jump_height_mm},
          {"adaptations", e.adaptations},
          {"finishing", e.finishing},
          {"gap_state", gap_name(e.gap_state)},
          {"gap_voltage_v", e.gap_voltage_v},
          {"filtered_voltage_v", e.filtered_voltage_v},
          {"path_speed_mm_s", e.path_speed_mm_s},
          {"backlog_mm", e.backlog_mm},
          {"retract_limit", e.retract_limit},
          {"jumping", e.jumping},
          {"jump_lift_mm", e.jump_lift_mm},
          {"jumps", e.jumps},
          {"orbit_radius_mm", e.orbit_radius_mm}};
}

}  // namespace

json process_json(const control::ServoStatus& s, const config::MachineProfile& p) {
  json j = json::object();
  j["power"] = {{"monitor", p.power.monitor},
                {"mains_ok", s.mains_ok},
                {"on_battery", s.on_battery},
                {"dc_link_v", s.dc_link_v}};
  if (p.broaching.present && (p.broaching.hold_kn > 0 || p.broaching.retract_kn > 0)) {
    j["load"] = {{"kn", s.load_kn},
                 {"action", control::to_string(s.load_action)},
                 {"hold_kn", p.broaching.hold_kn > 0 ? json(p.broaching.hold_kn) : json(nullptr)},
                 {"retract_kn", p.broaching.retract_kn > 0 ? json(p.broaching.retract_kn) : json(nullptr)}};
  }
  j["alarms"] = alarms_json(s, p.alarms);
  if (p.edm.present) j["edm"] = edm_json(s, p.edm.config);
  return j;
}

}  // namespace opencnc::hmi
