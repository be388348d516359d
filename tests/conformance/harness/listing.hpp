// SPDX-License-Identifier: GPL-3.0-or-later
// Canonical-call listings in rs274's `-g` text format: parsing, the motion subset, comparison.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace opencnc::conformance {

/// One call of a listing. The views point into the listing text, which must outlive the call.
struct CanonCall {
  std::uint32_t line = 0;   ///< 1-based line of the listing
  std::string_view name;    ///< "STRAIGHT_FEED"
  std::string_view args;    ///< the text between the parentheses
};

/// Every line of the form `<seq> N<label> NAME(args)`; other lines (PRINT output) are skipped.
/// Test code; any thread.
std::vector<CanonCall> parse_listing(std::string_view text);

/// The calls the conformance requirement compares: motion, feed, plane, tool change, spindle,
/// dwell, program end and stop.
bool in_motion_subset(std::string_view name);

/// The calls of `calls` that are in the motion subset, in order.
std::vector<CanonCall> motion_subset(std::span<const CanonCall> calls);

/// Arguments split at commas and blanks (rs274 separates some with a space only).
std::vector<std::string_view> split_arguments(std::string_view args);

/// Whether two argument lists match: same count, numbers within `tolerance` (rs274 prints four
/// decimals, so a last-digit rounding difference is exactly 1e-4), other tokens identical.
/// On a mismatch, `first_difference` (if given) receives the 0-based index of the first bad argument.
bool arguments_match(std::string_view a, std::string_view b, double tolerance,
                     std::size_t* first_difference = nullptr);

/// The result of comparing two call sequences.
struct Comparison {
  bool equal = true;
  std::string report;  ///< empty when equal; otherwise the first difference, readable
};

/// Compares `expected` with `actual` call by call (names and arguments). `expected_name` and
/// `actual_name` label the two sides in the report ("rs274", "opencnc").
Comparison compare_calls(std::span<const CanonCall> expected, std::span<const CanonCall> actual,
                         double tolerance, std::string_view expected_name, std::string_view actual_name);

}  // namespace opencnc::conformance
