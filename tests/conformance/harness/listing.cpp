// SPDX-License-Identifier: GPL-3.0-or-later
// Parsing and comparing rs274-format listings for the conformance harness.
#include "listing.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>

#include <fmt/format.h>

namespace opencnc::conformance {

namespace {

constexpr std::array kMotionSubset = {
    std::string_view{"STRAIGHT_TRAVERSE"},          std::string_view{"STRAIGHT_FEED"},
    std::string_view{"ARC_FEED"},                   std::string_view{"DWELL"},
    std::string_view{"SET_FEED_RATE"},              std::string_view{"SELECT_PLANE"},
    std::string_view{"CHANGE_TOOL"},                std::string_view{"START_SPINDLE_CLOCKWISE"},
    std::string_view{"START_SPINDLE_COUNTERCLOCKWISE"}, std::string_view{"STOP_SPINDLE_TURNING"},
    std::string_view{"SET_SPINDLE_SPEED"},          std::string_view{"PROGRAM_END"},
    std::string_view{"PROGRAM_STOP"},
};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_name_char(char c) { return (c >= 'A' && c <= 'Z') || is_digit(c) || c == '_'; }

// `    12 N0020  NAME(args)`: sequence number, N label, call. Returns nothing for other lines.
std::optional<CanonCall> parse_line(std::string_view line, std::uint32_t number) {
  std::size_t i = 0;
  while (i < line.size() && is_blank(line[i])) ++i;
  const std::size_t digits = i;
  while (i < line.size() && is_digit(line[i])) ++i;
  if (i == digits || i >= line.size() || line[i] != ' ') return std::nullopt;
  while (i < line.size() && line[i] == ' ') ++i;
  if (i >= line.size() || line[i] != 'N') return std::nullopt;
  while (i < line.size() && !is_blank(line[i])) ++i;
  while (i < line.size() && is_blank(line[i])) ++i;
  const std::size_t name_begin = i;
  while (i < line.size() && is_name_char(line[i])) ++i;
  if (i == name_begin || i >= line.size() || line[i] != '(') return std::nullopt;
  std::size_t close = line.size();
  while (close > i && line[close - 1] != ')') --close;
  if (close <= i) return std::nullopt;
  return CanonCall{number, line.substr(name_begin, i - name_begin), line.substr(i + 1, close - 1 - (i + 1))};
}

std::optional<double> as_number(std::string_view token) {
  double value = 0;
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ec != std::errc{} || ptr != end) return std::nullopt;
  return value;
}

std::string describe(const CanonCall& c) { return fmt::format("{}({})", c.name, c.args); }

}  // namespace

std::vector<CanonCall> parse_listing(std::string_view text) {
  std::vector<CanonCall> calls;
  std::uint32_t number = 0;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    const std::string_view line = text.substr(0, eol);
    ++number;
    if (auto call = parse_line(line, number)) calls.push_back(*call);
    if (eol == std::string_view::npos) break;
    text.remove_prefix(eol + 1);
  }
  return calls;
}

bool in_motion_subset(std::string_view name) {
  return std::find(kMotionSubset.begin(), kMotionSubset.end(), name) != kMotionSubset.end();
}

std::vector<CanonCall> motion_subset(std::span<const CanonCall> calls) {
  std::vector<CanonCall> out;
  std::copy_if(calls.begin(), calls.end(), std::back_inserter(out),
               [](const CanonCall& c) { return in_motion_subset(c.name); });
  return out;
}

std::vector<std::string_view> split_arguments(std::string_view args) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < args.size()) {
    while (i < args.size() && (args[i] == ',' || is_blank(args[i]))) ++i;
    const std::size_t begin = i;
    while (i < args.size() && args[i] != ',' && !is_blank(args[i])) ++i;
    if (i > begin) tokens.push_back(args.substr(begin, i - begin));
  }
  return tokens;
}

bool arguments_match(std::string_view a, std::string_view b, double tolerance, std::size_t* first_difference) {
  const auto ta = split_arguments(a);
  const auto tb = split_arguments(b);
  const std::size_t n = std::min(ta.size(), tb.size());
  for (std::size_t k = 0; k < n; ++k) {
    bool same = ta[k] == tb[k];
    if (!same) {
      const auto x = as_number(ta[k]);
      const auto y = as_number(tb[k]);
      // Slack of 1e-12 relative: 10000.0001 - 10000.0000 is a hair above 1e-4 in binary.
      same = x && y && std::abs(*x - *y) <= tolerance + 1e-12 * std::max(std::abs(*x), std::abs(*y));
    }
    if (!same) {
      if (first_difference) *first_difference = k;
      return false;
    }
  }
  if (ta.size() != tb.size()) {
    if (first_difference) *first_difference = n;
    return false;
  }
  return true;
}

Comparison compare_calls(std::span<const CanonCall> expected, std::span<const CanonCall> actual, double tolerance,
                         std::string_view expected_name, std::string_view actual_name) {
  const std::size_t width = std::max(expected_name.size(), actual_name.size());
  auto side = [&](std::string_view who, const CanonCall& c) {
    return fmt::format("  {:<{}} (listing line {}): {}\n", who, width, c.line, describe(c));
  };
  const std::size_t n = std::min(expected.size(), actual.size());
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t arg = 0;
    const bool same_name = expected[k].name == actual[k].name;
    if (same_name && arguments_match(expected[k].args, actual[k].args, tolerance, &arg)) continue;
    std::string r = fmt::format("motion calls differ at call #{} ({} has {} motion calls, {} has {}):\n", k + 1,
                                expected_name, expected.size(), actual_name, actual.size());
    r += side(expected_name, expected[k]);
    r += side(actual_name, actual[k]);
    if (same_name) r += fmt::format("  first different argument: #{} (tolerance {:g})\n", arg + 1, tolerance);
    if (k > 0) {
      r += fmt::format("  call #{} is the same in both: {} ({} line {}, {} line {})\n", k, describe(expected[k - 1]),
                       expected_name, expected[k - 1].line, actual_name, actual[k - 1].line);
    }
    return {false, r};
  }
  if (expected.size() == actual.size()) return {};
  const bool actual_short = actual.size() < expected.size();
  const auto& longer = actual_short ? expected : actual;
  std::string r = fmt::format("{} stops after {} motion calls; {} goes on with call #{}:\n",
                              actual_short ? actual_name : expected_name, n,
                              actual_short ? expected_name : actual_name, n + 1);
  r += side(actual_short ? expected_name : actual_name, longer[n]);
  if (n > 0) r += fmt::format("  last common call: {}\n", describe(expected[n - 1]));
  return {false, r};
}

}  // namespace opencnc::conformance
