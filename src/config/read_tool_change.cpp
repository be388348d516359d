// SPDX-License-Identifier: GPL-3.0-or-later
// [tool_change]: the tool-change position M6 moves to (machine coordinates) and its order.
#include <fmt/format.h>

#include <cmath>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

/// The machine's axis letters ("XYZ") for messages.
std::string axis_letters(const MachineProfile& profile) {
  std::string out;
  for (const AxisProfile& a : profile.axes) out += letter(a.axis);
  return out;
}

/// One axis of the position: an axis of the machine, a finite number, inside that axis' soft
/// limits (a wrapped axis has none).
void read_position_axis(Section& s, std::string_view key, MachineProfile& profile) {
  const auto axis = axis_from_letter(key);
  const AxisProfile* a = axis ? profile.find(*axis) : nullptr;
  if (a == nullptr) {
    s.error(key,
            fmt::format("{}: the machine has no axis {} (its axes: {})", s.key_path(key), key,
                        axis_letters(profile)),
            "config.axis-letter");
    return;
  }
  if (profile.tool_change.axes.has(*axis)) {
    s.error(key, fmt::format("{}: axis {} is named twice", s.key_path(key), letter(*axis)),
            "config.duplicate-axis");
    return;
  }
  const std::optional<double> v = s.number(key);
  if (!v) return;
  if (!std::isfinite(*v)) {
    s.error(key, fmt::format("{} must be a finite number", s.key_path(key)), "config.range");
    return;
  }
  const char* unit = is_rotary(*axis) ? "deg" : "mm";
  if (!a->wrapped && (*v < a->min_limit || *v > a->max_limit)) {
    s.error(key,
            fmt::format("{} = {} {} is outside {}'s soft limits [{}, {}] {}: M6 would move there",
                        s.key_path(key), show(*v), unit, letter(*axis), show(a->min_limit),
                        show(a->max_limit), unit),
            "config.range");
    return;
  }
  profile.tool_change.axes.set(*axis);
  profile.tool_change.position[*axis] = *v;
}

}  // namespace

void read_tool_change(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("tool_change");
  if (t == nullptr) return;
  Section s(*t, "tool_change", {"position", "z_first"}, top.reporter());
  ToolChangeProfile& tc = profile.tool_change;
  tc.z_first = s.boolean_or("z_first", tc.z_first);
  const toml::table* p = s.subtable("position");
  if (p == nullptr) {
    if (!s.has("position")) s.missing("position");
    return;
  }
  const toml::source_region& at = s.find("position")->source();
  tc.where = fmt::format("{}:{}:{}", at.path ? *at.path : std::string(), at.begin.line, at.begin.column);
  // Any letter is read here, so that one the machine lacks is named with the machine's axes.
  Section position(*p, "tool_change.position",
                   {"X", "Y", "Z", "A", "B", "C", "U", "V", "W", "x", "y", "z", "a", "b", "c", "u", "v", "w"},
                   top.reporter());
  bool named = false;
  for (const auto& [key, node] : *p) {
    if (!axis_from_letter(key.str())) continue;  // reported by the Section as an unknown key
    named = true;
    read_position_axis(position, key.str(), profile);
  }
  if (!named)
    s.error("position", "tool_change.position names no axis: give machine coordinates, e.g. { Z = 0.0 }",
            "config.missing-key");
}

}  // namespace opencnc::config::detail
