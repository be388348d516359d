// SPDX-License-Identifier: GPL-3.0-or-later
// The editable fields of a machining condition and the edit of one of them in the profile's
// text (its [[edm.condition]] element found by the condition's number, comments kept).
#include "condition_edit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <optional>

#include "opencnc/config/toml_edit.hpp"

namespace opencnc::config {

namespace {

constexpr std::array<ConditionField, 19> kFields{{
    {"on_time_us", "µs", "pulse on-time", nullptr},
    {"off_time_us", "µs", "pause between pulses", nullptr},
    {"peak_current_a", "A", "discharge current", nullptr},
    {"voltage_v", "V", "open-circuit voltage", nullptr},
    {"polarity", "", "electrode positive (+) or negative (−)", "+|-"},
    {"servo_reference_v", "V", "mean gap voltage the servo holds", nullptr},
    {"gain_mm_s_per_v", "mm/s/V", "path speed per volt off the reference", nullptr},
    {"max_forward_mm_s", "mm/s", "fastest feed into the work", nullptr},
    {"max_retract_mm_s", "mm/s", "fastest backing off a short", nullptr},
    {"filter_s", "s", "time constant of the gap voltage's filter", nullptr},
    {"short_timeout_s", "s", "a longer short stops the machine", nullptr},
    {"jump_height_mm", "mm", "how far a jump lifts the electrode", nullptr},
    {"jump_period_s", "s", "machining time between jumps (0: no jump)", nullptr},
    {"jump_speed_mm_s", "mm/s", "speed of the lift and the return", nullptr},
    {"jump_mode", "", "lift along the tool axis or back along the path", "axis|path"},
    {"orbit", "", "the orbit's shape", "none|circle|square|star"},
    {"orbit_radius_mm", "mm", "the orbit's final size", nullptr},
    {"orbit_step_mm", "mm", "growth per turn (0: all at once)", nullptr},
    {"orbit_period_s", "s", "one turn of the orbit", nullptr},
}};

/// "edm.condition.3.on_time_us" → (3, "on_time_us"); nullopt for any other key.
std::optional<std::pair<int, std::string>> condition_key_parts(std::string_view key) {
  constexpr std::string_view head = "edm.condition.";
  if (key.substr(0, head.size()) != head) return std::nullopt;
  key.remove_prefix(head.size());
  const std::size_t dot = key.find('.');
  if (dot == std::string_view::npos) return std::nullopt;
  int number = 0;
  const auto [end, ec] = std::from_chars(key.data(), key.data() + dot, number);
  if (ec != std::errc{} || end != key.data() + dot || number < 1 || number > 99) return std::nullopt;
  const std::string_view field = key.substr(dot + 1);
  const bool known =
      std::any_of(kFields.begin(), kFields.end(), [&](const ConditionField& f) { return field == f.key; });
  if (!known) return std::nullopt;
  return std::pair{number, std::string(field)};
}

}  // namespace

std::span<const ConditionField> condition_fields() {
  return kFields;
}

std::optional<double> condition_field_number(const machine::EdmCondition& c, std::string_view field) {
  const std::pair<std::string_view, double> numbers[] = {
      {"on_time_us", c.on_time_us},
      {"off_time_us", c.off_time_us},
      {"peak_current_a", c.peak_current_a},
      {"voltage_v", c.voltage_v},
      {"servo_reference_v", c.servo_reference_v},
      {"gain_mm_s_per_v", c.gain_mm_s_per_v},
      {"max_forward_mm_s", c.max_forward_mm_s},
      {"max_retract_mm_s", c.max_retract_mm_s},
      {"filter_s", c.filter_s},
      {"short_timeout_s", c.short_timeout_s},
      {"jump_height_mm", c.jump_height_mm},
      {"jump_period_s", c.jump_period_s},
      {"jump_speed_mm_s", c.jump_speed_mm_s},
      {"orbit_radius_mm", c.orbit_radius_mm},
      {"orbit_step_mm", c.orbit_step_mm},
      {"orbit_period_s", c.orbit_period_s},
  };
  for (const auto& [name, v] : numbers)
    if (name == field) return v;
  return std::nullopt;
}

std::string condition_field_text(const machine::EdmCondition& c, std::string_view field) {
  static constexpr const char* orbits[] = {"none", "circle", "square", "star"};
  if (field == "polarity") return c.polarity > 0 ? "+" : "-";
  if (field == "jump_mode") return c.jump_mode == machine::JumpMode::Path ? "path" : "axis";
  if (field == "orbit") return orbits[static_cast<std::size_t>(c.orbit)];
  const std::optional<double> v = condition_field_number(c, field);
  return v ? toml_number(*v) : "";
}

bool is_condition_key(std::string_view key) {
  return condition_key_parts(key).has_value();
}

namespace detail {

bool edit_condition(std::string& text, const MachineProfile& live, const std::string& key,
                    std::string_view value_toml, ProfileChange& change, std::string& error) {
  const auto parts = condition_key_parts(key);
  const machine::EdmConfig& edm = live.edm.config;
  const machine::EdmCondition* c = parts && live.edm.present ? edm.find(parts->first) : nullptr;
  if (c == nullptr) {
    error = parts ? fmt::format("{}: the profile has no machining condition {}", key, parts->first)
                  : fmt::format("{} is not a field of a machining condition that can be changed here", key);
    return false;
  }
  // The loader keeps the conditions in the file's order: the condition's index is its element.
  const auto element = static_cast<int>(c - edm.conditions.data());
  std::optional<std::string> next =
      with_toml_element_value(text, "edm.condition", element, parts->second, value_toml, error);
  if (!next) {
    error = fmt::format("{}: {}", live.source, error);
    return false;
  }
  text = std::move(*next);
  change = {key, condition_field_text(*c, parts->second), ""};
  return true;
}

std::string condition_value(const MachineProfile& profile, const std::string& key) {
  const auto parts = condition_key_parts(key);
  const machine::EdmCondition* c = parts ? profile.edm.config.find(parts->first) : nullptr;
  return c != nullptr ? condition_field_text(*c, parts->second) : "";
}

}  // namespace detail

}  // namespace opencnc::config
