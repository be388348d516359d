// SPDX-License-Identifier: GPL-3.0-or-later
// The editable fields of a machining condition and the edit of one of them in the profile's
// text (its [[edm.condition]] element found by the condition's number, comments kept).
#include "condition_edit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <functional>
#include <optional>

#include "opencnc/config/toml_edit.hpp"

namespace opencnc::config {

namespace {

constexpr std::array<ConditionField, 31> kFields{{
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
    {"orbit_finish", "", "the burn's end waits until the orbit is full and turned there", "true|false"},
    {"finish_timeout_s", "s", "a longer finishing cycle stops the machine", nullptr},
    {"lateral_servo", "", "the orbit follows the gap (slows, draws in on a short)", "true|false"},
    {"adaptive", "", "adaptive control within the bounds below", "true|false"},
    {"servo_reference_min_v", "V", "adaptive: lowest servo reference", nullptr},
    {"servo_reference_max_v", "V", "adaptive: highest servo reference", nullptr},
    {"gain_min_mm_s_per_v", "mm/s/V", "adaptive: lowest gain", nullptr},
    {"gain_max_mm_s_per_v", "mm/s/V", "adaptive: highest gain", nullptr},
    {"jump_period_min_s", "s", "adaptive: shortest jump period", nullptr},
    {"jump_period_max_s", "s", "adaptive: longest jump period", nullptr},
    {"jump_height_min_mm", "mm", "adaptive: lowest jump", nullptr},
    {"jump_height_max_mm", "mm", "adaptive: highest jump", nullptr},
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

int condition_to_copy(const machine::EdmConfig& edm, int number) {
  int below = 0, lowest = 0;
  for (int i = 0; i < edm.condition_count; ++i) {
    const int n = edm.conditions[static_cast<std::size_t>(i)].number;
    if (n < number && n > below) below = n;
    if (lowest == 0 || n < lowest) lowest = n;
  }
  return below != 0 ? below : lowest;
}

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
      {"finish_timeout_s", c.finish_timeout_s},
      {"servo_reference_min_v", c.servo_reference_min_v},
      {"servo_reference_max_v", c.servo_reference_max_v},
      {"gain_min_mm_s_per_v", c.gain_min_mm_s_per_v},
      {"gain_max_mm_s_per_v", c.gain_max_mm_s_per_v},
      {"jump_period_min_s", c.jump_period_min_s},
      {"jump_period_max_s", c.jump_period_max_s},
      {"jump_height_min_mm", c.jump_height_min_mm},
      {"jump_height_max_mm", c.jump_height_max_mm},
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
  if (field == "orbit_finish") return c.orbit_finish ? "true" : "false";
  if (field == "lateral_servo") return c.lateral_servo ? "true" : "false";
  if (field == "adaptive") return c.adaptive ? "true" : "false";
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

namespace {

/// The element of condition `c` in the file: the loader keeps the conditions in the file's order.
int element_of(const machine::EdmConfig& edm, const machine::EdmCondition* c) {
  return static_cast<int>(c - edm.conditions.data());
}

/// Adds the conditions of `changes` to `text` (a copy of each one's source after the last
/// element); `count` goes up by each. False with `error`.
bool add_conditions(std::string& text, const machine::EdmConfig& edm,
                    std::span<const ConditionChange> changes, int& count, std::vector<ProfileChange>& out,
                    std::string& error) {
  std::vector<int> added;
  for (const ConditionChange& c : changes) {
    if (c.remove) continue;
    if (c.number < 1 || c.number > 99) {
      error = fmt::format("a machining condition's number is 1 to 99, not {}", c.number);
      return false;
    }
    if (edm.find(c.number) != nullptr || std::find(added.begin(), added.end(), c.number) != added.end()) {
      error = fmt::format("condition {} exists already: change its values instead", c.number);
      return false;
    }
    const machine::EdmCondition* from = edm.find(c.from);
    if (from == nullptr) {
      error = fmt::format("there is no condition {} to copy the new condition {} from", c.from, c.number);
      return false;
    }
    if (++count > machine::kMaxEdmConditions) {
      error = fmt::format(
          "the machine holds at most {} machining conditions: delete one before adding condition {}",
          machine::kMaxEdmConditions, c.number);
      return false;
    }
    std::optional<std::string> next = with_toml_element_copy(
        text, "edm.condition", element_of(edm, from), "number", std::to_string(c.number),
        fmt::format("Condition {}: a copy of condition {}.", c.number, c.from), error);
    if (!next) return false;
    text = std::move(*next);
    added.push_back(c.number);
    out.push_back(
        {fmt::format("edm.condition.{}", c.number), "none", fmt::format("a copy of condition {}", c.from)});
  }
  return true;
}

/// Deletes the conditions of `changes` from `text` (the last element first, so that the others'
/// places stand); `count` goes down by each. False with `error`.
bool delete_conditions(std::string& text, const machine::EdmConfig& edm,
                       std::span<const ConditionChange> changes, std::span<const ProfileKeyEdit> edits,
                       int& count, std::vector<ProfileChange>& out, std::string& error) {
  std::vector<int> elements;
  for (const ConditionChange& c : changes) {
    if (!c.remove) continue;
    const machine::EdmCondition* d = edm.find(c.number);
    if (d == nullptr) {
      error = fmt::format("the profile has no machining condition {} to delete", c.number);
      return false;
    }
    const std::string key = fmt::format("edm.condition.{}", c.number);
    const bool edited = std::any_of(edits.begin(), edits.end(), [&](const ProfileKeyEdit& e) {
      return e.key.size() > key.size() && e.key.compare(0, key.size() + 1, key + ".") == 0;
    });
    if (edited || std::find(elements.begin(), elements.end(), element_of(edm, d)) != elements.end()) {
      error = fmt::format("condition {} is deleted and changed (or deleted twice) in one request", c.number);
      return false;
    }
    if (--count < 1) {
      error =
          fmt::format("condition {} is the machine's last machining condition: an EDM needs one", c.number);
      return false;
    }
    elements.push_back(element_of(edm, d));
    out.push_back({key, "defined", "deleted"});
  }
  std::sort(elements.begin(), elements.end(), std::greater<>());
  for (const int element : elements) {
    std::optional<std::string> next = without_toml_element(text, "edm.condition", element, error);
    if (!next) return false;
    text = std::move(*next);
  }
  return true;
}

}  // namespace

bool change_conditions(std::string& text, const MachineProfile& live,
                       std::span<const ConditionChange> changes, std::span<const ProfileKeyEdit> edits,
                       std::vector<ProfileChange>& changes_out, std::string& error) {
  const machine::EdmConfig& edm = live.edm.config;
  int count = edm.condition_count;
  if (!live.edm.present)
    error = "the machine has no [edm] section: it has no machining conditions to add or delete";
  else if (add_conditions(text, edm, changes, count, changes_out, error) &&
           delete_conditions(text, edm, changes, edits, count, changes_out, error))
    return true;
  error = fmt::format("{}: {}", live.source, error);
  return false;
}

std::string condition_value(const MachineProfile& profile, const std::string& key) {
  const auto parts = condition_key_parts(key);
  const machine::EdmCondition* c = parts ? profile.edm.config.find(parts->first) : nullptr;
  return c != nullptr ? condition_field_text(*c, parts->second) : "";
}

}  // namespace detail

}  // namespace opencnc::config
