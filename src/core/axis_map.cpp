// SPDX-License-Identifier: GPL-3.0-or-later
// Reading and writing axis exchange maps.
#include "opencnc/core/axis_map.hpp"

#include <fmt/format.h>

namespace opencnc {

namespace {

int axis_index(char c) noexcept {
  const char up = (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
  const auto pos = kAxisLetters.find(up);
  return pos == std::string_view::npos ? -1 : static_cast<int>(pos);
}

std::string_view trim(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string parse_axis_map(std::string_view text, AxisMap& map) {
  AxisMap result = identity_axis_map();
  std::array<bool, kAxisCount> named{};
  while (!trim(text).empty()) {
    const std::size_t comma = text.find(',');
    const std::string_view item = trim(text.substr(0, comma));
    text = comma == std::string_view::npos ? std::string_view() : text.substr(comma + 1);
    const std::size_t eq = item.find('=');
    const std::string_view from = eq == std::string_view::npos ? item : trim(item.substr(0, eq));
    const std::string_view to = eq == std::string_view::npos ? std::string_view() : trim(item.substr(eq + 1));
    if (from.size() != 1 || to.size() != 1 || axis_index(from[0]) < 0 || axis_index(to[0]) < 0)
      return fmt::format("'{}' is not LETTER=AXIS (axes are X Y Z A B C U V W)", item);
    const int program = axis_index(from[0]);
    const auto machine = static_cast<Axis>(axis_index(to[0]));
    if (named[static_cast<std::size_t>(program)]) return fmt::format("{} is mapped twice", kAxisLetters[static_cast<std::size_t>(program)]);
    if (is_rotary(static_cast<Axis>(program)) != is_rotary(machine))
      return fmt::format("{}={}: a linear axis cannot drive a rotary one or the reverse", from, to);
    named[static_cast<std::size_t>(program)] = true;
    result[static_cast<std::size_t>(program)] = machine;
  }
  // Named letters need distinct axes; a letter not named keeps its axis unless a named one
  // took it, and then takes the first axis of its kind left free (so "X=Y" alone is the
  // exchange X=Y,Y=X).
  std::array<bool, kAxisCount> taken{};   // by a named letter
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    if (!named[i]) continue;
    const auto target = static_cast<std::size_t>(index(result[i]));
    if (taken[target]) return fmt::format("two program letters drive {}", kAxisLetters[target]);
    taken[target] = true;
  }
  std::array<bool, kAxisCount> used = taken;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    if (!named[i] && !taken[i]) used[i] = true;   // keeps its own axis
  }
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    if (named[i] || !taken[i]) continue;   // not displaced
    for (std::size_t free = 0; free < kAxisCount; ++free) {
      if (used[free] || is_rotary(static_cast<Axis>(free)) != is_rotary(static_cast<Axis>(i))) continue;
      result[i] = static_cast<Axis>(free);
      used[free] = true;
      break;
    }
  }
  map = result;
  return {};
}

std::string format_axis_map(const AxisMap& map) {
  std::string out;
  for (int i = 0; i < kAxisCount; ++i) {
    const Axis a = map[static_cast<std::size_t>(i)];
    if (index(a) == i) continue;
    if (!out.empty()) out += ',';
    out += kAxisLetters[static_cast<std::size_t>(i)];
    out += '=';
    out += letter(a);
  }
  return out;
}

}  // namespace opencnc
