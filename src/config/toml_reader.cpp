// SPDX-License-Identifier: GPL-3.0-or-later
// Typed, bounded, positioned reading of TOML tables.
#include "toml_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace opencnc::config::detail {

void Reporter::add(Severity severity, const toml::source_region* at, std::string message, std::string code) {
  Diagnostic d;
  d.severity = severity;
  d.message = std::move(message);
  d.code = std::move(code);
  d.file = fallback_file_;
  if (at != nullptr && at->begin.line > 0) {
    if (at->path) d.file = *at->path;
    d.line = at->begin.line;
    d.col = at->begin.column;
  }
  out_.add(std::move(d));
}

void Reporter::error(const toml::source_region* at, std::string message, std::string code) {
  add(Severity::Error, at, std::move(message), std::move(code));
}

void Reporter::warning(const toml::source_region* at, std::string message, std::string code) {
  add(Severity::Warning, at, std::move(message), std::move(code));
}

std::string_view type_name(const toml::node& node) noexcept {
  switch (node.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date or time";
  }
}

std::string show(double value) {
  return fmt::format("{}", value);
}

Section::Section(const toml::table& table, std::string path, std::initializer_list<std::string_view> allowed,
                 Reporter& reporter)
    : table_(table), path_(std::move(path)), reporter_(reporter) {
  for (const auto& [key, node] : table) {
    if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
    std::string list;
    for (std::string_view a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    const std::string where = path_.empty() ? "at the top level" : "in [" + path_ + "]";
    reporter_.error(&key.source(),
                    fmt::format("unknown key '{}' {}; allowed keys: {}", key.str(), where, list),
                    "config.unknown-key");
  }
}

std::string Section::key_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

const toml::source_region* Section::at(std::string_view key) const noexcept {
  const toml::node* n = find(key);
  return n != nullptr ? &n->source() : &table_.source();
}

void Section::error(std::string_view key, std::string message, std::string code) {
  reporter_.error(at(key), std::move(message), std::move(code));
}

void Section::warning(std::string_view key, std::string message, std::string code) {
  reporter_.warning(at(key), std::move(message), std::move(code));
}

void Section::missing(std::string_view key) {
  const std::string where = path_.empty() ? "the profile" : "[" + path_ + "]";
  error(key, fmt::format("{} needs {}", where, key), "config.missing-key");
}

void Section::reject(std::string_view key, std::string_view reason) {
  if (has(key)) error(key, fmt::format("{} {}", key_path(key), reason), "config.not-applicable");
}

std::optional<double> Section::number(std::string_view key, Bound bound) {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  double v = 0;
  if (const auto* i = n->as_integer()) {
    v = static_cast<double>(i->get());
  } else if (const auto* f = n->as_floating_point()) {
    v = f->get();
  } else {
    error(key, fmt::format("{} must be a number, not {}", key_path(key), type_name(*n)), "config.type");
    return std::nullopt;
  }
  if (!std::isfinite(v)) {
    error(key, fmt::format("{} must be a finite number (it is {})", key_path(key), show(v)), "config.range");
    return std::nullopt;
  }
  if (bound == Bound::Positive && !(v > 0)) {
    error(key, fmt::format("{} must be greater than 0 (it is {})", key_path(key), show(v)), "config.range");
    return std::nullopt;
  }
  if (bound == Bound::NonNegative && v < 0) {
    error(key, fmt::format("{} must not be negative (it is {})", key_path(key), show(v)), "config.range");
    return std::nullopt;
  }
  return v;
}

double Section::number_or(std::string_view key, double fallback, Bound bound) {
  return number(key, bound).value_or(fallback);
}

double Section::required_number(std::string_view key, Bound bound) {
  if (!has(key)) {
    missing(key);
    return 0;
  }
  return number(key, bound).value_or(0);
}

std::optional<std::int64_t> Section::integer(std::string_view key, std::int64_t min, std::int64_t max) {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  const auto* i = n->as_integer();
  if (i == nullptr) {
    const auto* f = n->as_floating_point();
    error(key,
          f != nullptr ? fmt::format("{} must be a whole number (it is {})", key_path(key), show(f->get()))
                       : fmt::format("{} must be a whole number, not {}", key_path(key), type_name(*n)),
          "config.type");
    return std::nullopt;
  }
  if (i->get() < min || i->get() > max) {
    error(key, fmt::format("{} must be between {} and {} (it is {})", key_path(key), min, max, i->get()),
          "config.range");
    return std::nullopt;
  }
  return i->get();
}

bool Section::boolean_or(std::string_view key, bool fallback) {
  const toml::node* n = find(key);
  if (n == nullptr) return fallback;
  if (const auto* b = n->as_boolean()) return b->get();
  error(key, fmt::format("{} must be true or false, not {}", key_path(key), type_name(*n)), "config.type");
  return fallback;
}

std::optional<std::string> Section::string(std::string_view key) {
  const toml::node* n = find(key);
  if (n == nullptr) return std::nullopt;
  if (const auto* s = n->as_string()) return s->get();
  error(key, fmt::format("{} must be a string, not {}", key_path(key), type_name(*n)), "config.type");
  return std::nullopt;
}

const toml::table* Section::subtable(std::string_view key) {
  const toml::node* n = find(key);
  if (n == nullptr) return nullptr;
  if (const auto* t = n->as_table()) return t;
  error(key, fmt::format("{} must be a table ([{}]), not {}", key_path(key), key_path(key), type_name(*n)),
        "config.type");
  return nullptr;
}

}  // namespace opencnc::config::detail
