// SPDX-License-Identifier: GPL-3.0-or-later
// Reading one TOML table key by key with type and range checks and positioned diagnostics.
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "opencnc/core/diagnostic.hpp"

namespace opencnc::config::detail {

/// Collects diagnostics, placing each at a TOML source position.
class Reporter {
 public:
  Reporter(Diagnostics& out, std::string fallback_file)
      : out_(out), fallback_file_(std::move(fallback_file)) {}

  /// `at` may be null (no position known).
  void error(const toml::source_region* at, std::string message, std::string code);
  void warning(const toml::source_region* at, std::string message, std::string code);
  bool has_errors() const noexcept { return out_.has_errors(); }
  /// Errors so far: a reader compares it before and after a part to know whether that part was sound.
  std::size_t error_count() const noexcept { return out_.error_count(); }

 private:
  void add(Severity severity, const toml::source_region* at, std::string message, std::string code);
  Diagnostics& out_;
  std::string fallback_file_;
};

/// Constraint on a number.
enum class Bound : std::uint8_t { Any, Positive, NonNegative };

/// One table of the profile. The constructor reports every key that is not in `allowed`
/// (listing the allowed ones); the getters check types and bounds and report at the value.
/// A getter that finds a bad value reports it and returns the fallback (or nullopt), so
/// reading goes on and all problems of a file are found in one pass.
class Section {
 public:
  Section(const toml::table& table, std::string path, std::initializer_list<std::string_view> allowed,
          Reporter& reporter);

  const toml::table& table() const noexcept { return table_; }
  Reporter& reporter() const noexcept { return reporter_; }
  /// "axis.x" (empty for the top level).
  const std::string& path() const noexcept { return path_; }
  /// "axis.x.max_velocity".
  std::string key_path(std::string_view key) const;
  const toml::node* find(std::string_view key) const noexcept { return table_.get(key); }
  bool has(std::string_view key) const noexcept { return find(key) != nullptr; }

  std::optional<double> number(std::string_view key, Bound bound = Bound::Any);
  double number_or(std::string_view key, double fallback, Bound bound = Bound::Any);
  /// Reports a missing key and returns 0 when it is absent.
  double required_number(std::string_view key, Bound bound = Bound::Any);
  std::optional<std::int64_t> integer(std::string_view key, std::int64_t min, std::int64_t max);
  bool boolean_or(std::string_view key, bool fallback);
  std::optional<std::string> string(std::string_view key);
  /// The sub-table `key`, or nullptr (reported if `key` holds something else).
  const toml::table* subtable(std::string_view key);

  /// One of the named options; reports any other word.
  template <typename E>
  E choice(std::string_view key, std::initializer_list<std::pair<std::string_view, E>> options, E fallback) {
    const auto word = string(key);
    if (!word) return fallback;
    for (const auto& [name, value] : options) {
      if (*word == name) return value;
    }
    std::string names;
    for (const auto& option : options) names += (names.empty() ? "" : ", ") + std::string(option.first);
    error(key, key_path(key) + " must be one of " + names + " (it is \"" + *word + "\")", "config.range");
    return fallback;
  }

  /// Reports at the value of `key`, or at the table when the key is absent.
  void error(std::string_view key, std::string message, std::string code);
  void warning(std::string_view key, std::string message, std::string code);
  /// Reports that `key` is needed and absent.
  void missing(std::string_view key);
  /// Reports `key`, if present, as not applying here, with the reason.
  void reject(std::string_view key, std::string_view reason);

 private:
  const toml::source_region* at(std::string_view key) const noexcept;

  const toml::table& table_;
  std::string path_;
  Reporter& reporter_;
};

/// "string", "integer", … for messages.
std::string_view type_name(const toml::node& node) noexcept;
/// A number as we print it in messages (shortest form that reads back the same).
std::string show(double value);

}  // namespace opencnc::config::detail
