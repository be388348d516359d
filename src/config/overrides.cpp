// SPDX-License-Identifier: GPL-3.0-or-later
// Parsing `key=value` overrides as one-line TOML documents and merging them into a profile.
#include "overrides.hpp"

#include <fmt/format.h>

#include <cctype>
#include <memory>
#include <optional>

namespace opencnc::config::detail {

namespace {

constexpr std::string_view kSource = "--set";

bool same_letters(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  }
  return true;
}

/// The key of `table` that `key` means: itself, or under [axis] the same letter in the
/// other case (axis.x=… must reach a file's [axis.X]).
std::string resolve_key(const toml::table& table, std::string_view key, bool fold_case) {
  if (fold_case) {
    for (const auto& [existing, node] : table) {
      if (same_letters(existing.str(), key)) return std::string(existing.str());
    }
  }
  return std::string(key);
}

void merge(toml::table& into, toml::table& from, bool at_root, bool fold_case) {
  for (auto&& entry : from) {
    // Named references, not a structured binding: lambdas capture them in every compiler.
    const toml::key& key = entry.first;
    toml::node& node = entry.second;
    const std::string target = resolve_key(into, key.str(), fold_case);
    toml::node* existing = into.get(target);
    if (existing != nullptr && existing->is_table() && node.is_table()) {
      merge(*existing->as_table(), *node.as_table(), false, at_root && key.str() == "axis");
      continue;
    }
    // Moving (not copying) keeps the value's source position; a new key keeps its own.
    node.visit([&](auto& value) {
      if (target == key.str()) {
        into.insert_or_assign(key, std::move(value));
      } else {
        into.insert_or_assign(target, std::move(value));
      }
    });
  }
}

struct ParseFailure {
  std::string description;
  toml::source_region where;
};

/// `text` as a TOML document on line `line` of "--set" (the leading newlines put it there).
std::optional<toml::table> parse_line(const std::string& text, std::uint32_t line, ParseFailure* failure) {
  const std::string doc = std::string(line - 1, '\n') + text;
  try {
    return toml::parse(doc, kSource);
  } catch (const toml::parse_error& e) {
    if (failure != nullptr) *failure = {std::string(e.description()), e.source()};
    return std::nullopt;
  }
}

/// `inf`, `nan` (and signed ones) are TOML numbers a bare word must not turn into strings.
bool looks_numeric(std::string_view v) {
  while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.remove_suffix(1);
  return v == "inf" || v == "nan";
}

/// The override with its value as a TOML basic string ("fanuc" for a bare fanuc).
std::string quoted(std::string_view key, std::string_view value) {
  std::string out(key);
  out += "=\"";
  for (char c : value) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  out += '"';
  return out;
}

}  // namespace

bool apply_overrides(toml::table& root, std::span<const std::string> overrides, Reporter& reporter) {
  bool ok = true;
  std::uint32_t line = 0;
  for (const std::string& text : overrides) {
    ++line;
    toml::source_region where;
    where.begin = {line, 1};
    where.end = where.begin;
    where.path = std::make_shared<const std::string>(kSource);
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0) {
      reporter.error(&where, fmt::format("override '{}' is not key=value", text), "config.override");
      ok = false;
      continue;
    }
    ParseFailure first;
    auto doc = parse_line(text, line, &first);
    // A bare word (fanuc, stepper, a path) is a string; what looks like TOML stays an error.
    const std::string_view value = std::string_view(text).substr(eq + 1);
    const auto start = value.find_first_not_of(" \t");
    // A bare word is a string; what starts like a number or a TOML value (1e999, 2.5.1, [1, 2)
    // stays the TOML error, which says what is wrong with it.
    const bool bare = start != std::string_view::npos &&
                      std::string_view("[{\"'+-.0123456789").find(value[start]) == std::string_view::npos &&
                      !looks_numeric(value.substr(start));
    if (!doc && bare)
      doc = parse_line(quoted(std::string_view(text).substr(0, eq), value.substr(start)), line, nullptr);
    if (!doc) {
      reporter.error(&first.where,
                     fmt::format("override '{}' is not valid TOML: {}", text, first.description),
                     "config.override");
      ok = false;
      continue;
    }
    merge(root, *doc, true, false);
  }
  return ok;
}

}  // namespace opencnc::config::detail
