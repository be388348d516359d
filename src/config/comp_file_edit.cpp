// SPDX-License-Identifier: GPL-3.0-or-later
// An axis' pitch-error table written back into its LinuxCNC comp file, comment lines kept.
#include "opencnc/config/comp_file_edit.hpp"

#include <fmt/format.h>

#include <toml++/toml.h>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <tuple>

#include "opencnc/core/atomic_file.hpp"

namespace opencnc::config {

namespace {

/// A number as the comp file holds it: 15 significant digits, so that nominal + error is written
/// as the sum a person would (99.996, not 99.99599999999999), exactly enough for the loader's
/// 1e-9 resolution of type 0 errors at positions up to 10 m.
std::string comp_number(double v) {
  if (v == 0) return "0";  // not "-0"
  return fmt::format("{:.15g}", v);
}

/// "[0, -0.002]" → its numbers; nullopt with `error` naming `what`.
std::optional<std::vector<double>> numbers(std::string_view value, std::string_view what,
                                           std::string& error) {
  toml::table parsed;
  try {
    parsed = toml::parse(fmt::format("v = {}", value));
  } catch (const toml::parse_error&) {
  }
  const toml::array* a = parsed["v"].as_array();
  if (a == nullptr) {
    error = fmt::format("{} must be an array of numbers, not {}", what, value);
    return std::nullopt;
  }
  std::vector<double> out;
  for (const toml::node& e : *a) {
    const std::optional<double> v = e.value<double>();
    if (!v || !std::isfinite(*v)) {
      error = fmt::format("{} must hold finite numbers only", what);
      return std::nullopt;
    }
    out.push_back(*v);
  }
  return out;
}

bool is_point_line(std::string_view line) {
  const std::size_t first = line.find_first_not_of(" \t\r\n");
  return first != std::string_view::npos && line[first] != '#';
}

}  // namespace

std::string comp_file_with_table(std::string_view old_text, int type, std::span<const double> positions,
                                 std::span<const double> forward, std::span<const double> reverse) {
  auto point = [&](std::size_t k) {
    const double x = positions[k];
    const double up = type == 0 ? x + forward[k] : -forward[k];
    const double down = type == 0 ? x + reverse[k] : -reverse[k];
    return fmt::format("{} {} {}\n", comp_number(x), comp_number(up), comp_number(down));
  };
  std::string out;
  std::size_t next = 0, end_of_points = 0;
  std::size_t at = 0;
  while (at < old_text.size()) {
    const std::size_t eol = old_text.find('\n', at);
    const std::size_t stop = eol == std::string_view::npos ? old_text.size() : eol + 1;
    const std::string_view line = old_text.substr(at, stop - at);
    at = stop;
    if (!is_point_line(line)) {
      out += line;
      if (line.back() != '\n') out += '\n';
      continue;
    }
    if (next < positions.size()) {
      out += point(next++);
      end_of_points = out.size();
    }
  }
  std::string rest;
  for (; next < positions.size(); ++next) rest += point(next);
  out.insert(end_of_points, rest);
  return out;
}

std::optional<FileText> edit_comp_file(const AxisProfile& a, const std::optional<std::string>& forward,
                                       const std::optional<std::string>& reverse,
                                       const std::optional<std::string>& positions, std::string& error) {
  const CompensationProfile& c = a.compensation;
  const std::string base =
      fmt::format("axis.{}.compensation", static_cast<char>(std::tolower(letter(a.axis))));
  std::string text, why;
  if (!read_file(c.comp_path, text, &why)) {
    error = fmt::format("{}: cannot read the comp file: {}", c.comp_path, why);
    return std::nullopt;
  }
  if (text_digest(text) != c.comp_digest) {
    error = fmt::format(
        "{} changed on disk since the controller loaded it: restart the controller to load it before "
        "changing the table here",
        c.comp_path);
    return std::nullopt;
  }
  std::vector<double> f = c.forward, r = c.reverse, x = c.positions;
  for (const auto& [value, out, name] :
       {std::tuple{&forward, &f, "forward"}, std::tuple{&reverse, &r, "reverse"},
        std::tuple{&positions, &x, "positions"}}) {
    if (!*value) continue;
    auto v = numbers(**value, fmt::format("{}.{}", base, name), error);
    if (!v) return std::nullopt;
    *out = std::move(*v);
  }
  if (f.size() != r.size() || f.size() != x.size()) {
    error = fmt::format(
        "{}: the comp file {} needs as many positions as errors each way ({} positions, {} forward, {} "
        "reverse)",
        base, c.comp_file, x.size(), f.size(), r.size());
    return std::nullopt;
  }
  return FileText{c.comp_path, comp_file_with_table(text, c.comp_file_type, x, f, r)};
}

bool CompFileEdits::add(const AxisProfile& a, std::string_view name, const std::string& value,
                        std::string& error) {
  if (name != "forward" && name != "reverse" && name != "positions") {
    error = fmt::format(
        "axis.{}.compensation.{}: the table is in the comp file {}, which lists each point's position: "
        "give positions",
        static_cast<char>(std::tolower(letter(a.axis))), name, a.compensation.comp_file);
    return false;
  }
  auto it = std::find_if(axes_.begin(), axes_.end(), [&](const Axis& x) { return x.axis == &a; });
  if (it == axes_.end()) it = axes_.insert(axes_.end(), Axis{&a, {}, {}, {}});
  (name == "forward" ? it->forward : name == "reverse" ? it->reverse : it->positions) = value;
  return true;
}

bool CompFileEdits::texts(std::vector<FileText>& out, std::string& error) const {
  for (const Axis& x : axes_) {
    std::optional<FileText> f = edit_comp_file(*x.axis, x.forward, x.reverse, x.positions, error);
    if (!f) return false;
    out.push_back(std::move(*f));
  }
  return true;
}

}  // namespace opencnc::config
