// SPDX-License-Identifier: GPL-3.0-or-later
// Diagnostics with a source position, formatted as `file:line:col: error: message`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace opencnc {

enum class Severity : std::uint8_t { Note, Warning, Error };

/// One message a person can act on. Line and column are 1-based; 0 means "not known".
struct Diagnostic {
  Severity severity = Severity::Error;
  std::string file;
  std::uint32_t line = 0;
  std::uint32_t col = 0;
  std::string message;
  /// Stable machine-readable id of the problem (e.g. "gcode.feed-zero"); empty when none.
  /// Tests and front ends match on it, never on the wording.
  std::string code;

  /// `file:line:col: error: message` (the parts that are unknown are left out).
  std::string format() const;
};

/// Diagnostics of one run, in the order they were found.
class Diagnostics {
 public:
  void add(Diagnostic d) { items_.push_back(std::move(d)); }
  void error(std::string file, std::uint32_t line, std::uint32_t col, std::string message,
             std::string code = {}) {
    add({Severity::Error, std::move(file), line, col, std::move(message), std::move(code)});
  }
  void warning(std::string file, std::uint32_t line, std::uint32_t col, std::string message,
               std::string code = {}) {
    add({Severity::Warning, std::move(file), line, col, std::move(message), std::move(code)});
  }
  bool has_errors() const noexcept;
  std::size_t error_count() const noexcept;
  std::size_t warning_count() const noexcept;
  const std::vector<Diagnostic>& items() const noexcept { return items_; }
  bool empty() const noexcept { return items_.empty(); }
  void clear() noexcept { items_.clear(); }

 private:
  std::vector<Diagnostic> items_;
};

}  // namespace opencnc
