// SPDX-License-Identifier: GPL-3.0-or-later
// Replacing one axis' compensation table in a profile's text, line by line, then checking that
// nothing else changed (the TOML trees compared without that table).
#include "opencnc/config/profile_writer.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <cctype>
#include <cmath>
#include <vector>

#include "toml_lines.hpp"

namespace opencnc::config {

namespace {

using detail::header_key;
using detail::split_lines;
using detail::table_end;
using Line = detail::TomlLine;

std::string number(double v) {
  // Micrometres to a tenth (what a laser measures), without a trailing "-0.0".
  const double r = std::round(v * 1e7) / 1e7;
  return fmt::format("{}", r == 0 ? 0.0 : r);
}

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + number(v[i]);
  return s + "]";
}

/// Everything but `axis`'s compensation must read back the same.
bool same_but_compensation(toml::table a, toml::table b, char letter) {
  for (toml::table* t : {&a, &b}) {
    if (toml::table* axes = (*t)["axis"].as_table()) {
      for (auto&& [k, v] : *axes) {
        if (k.str().size() == 1 && std::tolower(static_cast<unsigned char>(k.str()[0])) == letter &&
            v.is_table())
          v.as_table()->erase("compensation");
      }
    }
  }
  return a == b;
}

}  // namespace

std::string compensation_toml(Axis axis, const CompensationProfile& c) {
  const char l = static_cast<char>(std::tolower(letter(axis)));
  std::string s = fmt::format("[axis.{}.compensation]\n", l);
  s += "# Measured by opencnc calibrate --positioning: errors (actual − nominal, mm) moving up and down.\n";
  if (!c.positions.empty()) {
    const double interval = c.positions.size() > 1 ? c.positions[1] - c.positions[0] : 1.0;
    s += fmt::format("start = {}\ninterval = {}\n", number(c.positions.front()), number(interval));
    s += "forward = " + list(c.forward) + "\n";
    s += "reverse = " + list(c.reverse) + "\n";
  }
  s += fmt::format("backlash = {}\ntakeup_velocity = {}\ntakeup_acceleration = {}\n", number(c.backlash),
                   number(c.takeup_velocity), number(c.takeup_acceleration));
  return s;
}

std::optional<std::string> with_compensation(std::string_view text, Axis axis, const CompensationProfile& c,
                                             std::string& error) {
  const char l = static_cast<char>(std::tolower(letter(axis)));
  const std::string own = fmt::format("axis.{}", l), table = own + ".compensation";
  const std::vector<Line> lines = split_lines(text);
  std::size_t replace_from = lines.size(), replace_to = lines.size(), insert_at = lines.size();
  bool has_axis = false;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string key = header_key(lines[i].text);
    if (key == table) {
      replace_from = i;
      replace_to = table_end(lines, i);
    } else if (key == own || key.rfind(own + ".", 0) == 0) {
      has_axis = true;
      insert_at = table_end(lines, i);
    }
  }
  if (!has_axis) {
    error = fmt::format("the profile has no [axis.{}] table to put the compensation after", l);
    return std::nullopt;
  }
  const std::string section = compensation_toml(axis, c);
  std::string out;
  if (replace_from < lines.size()) {
    out.append(text.substr(0, lines[replace_from].begin));
    out += section;
    out.append(text.substr(replace_to < lines.size() ? lines[replace_to].begin : text.size()));
  } else {
    const std::size_t at = insert_at < lines.size() ? lines[insert_at].begin : text.size();
    out.append(text.substr(0, at));
    if (!out.empty() && out.back() != '\n') out += '\n';
    out += "\n" + section;
    out.append(text.substr(at));
  }
  // The edit must give exactly this table, and nothing else may have changed.
  try {
    const toml::table before = toml::parse(text), after = toml::parse(out);
    if (!same_but_compensation(before, after, l)) {
      error = fmt::format(
          "the compensation of {} is not a table of its own in the profile ([axis.{}.compensation]); "
          "edit it by hand",
          letter(axis), l);
      return std::nullopt;
    }
  } catch (const toml::parse_error& e) {
    error = fmt::format("the profile would not read back: {}", e.description());
    return std::nullopt;
  }
  return out;
}

}  // namespace opencnc::config
