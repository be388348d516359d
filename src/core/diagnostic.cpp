// SPDX-License-Identifier: GPL-3.0-or-later
// Formatting and counting of diagnostics.
#include "opencnc/core/diagnostic.hpp"

#include <algorithm>
#include <fmt/format.h>

namespace opencnc {

namespace {
const char* severity_name(Severity s) {
  switch (s) {
    case Severity::Note: return "note";
    case Severity::Warning: return "warning";
    case Severity::Error: return "error";
  }
  return "error";
}
}  // namespace

std::string Diagnostic::format() const {
  std::string out;
  if (!file.empty()) {
    out += file;
    if (line > 0) {
      out += fmt::format(":{}", line);
      if (col > 0) out += fmt::format(":{}", col);
    }
    out += ": ";
  }
  out += severity_name(severity);
  out += ": ";
  out += message;
  return out;
}

bool Diagnostics::has_errors() const noexcept { return error_count() > 0; }

std::size_t Diagnostics::error_count() const noexcept {
  return static_cast<std::size_t>(std::count_if(
      items_.begin(), items_.end(), [](const Diagnostic& d) { return d.severity == Severity::Error; }));
}

std::size_t Diagnostics::warning_count() const noexcept {
  return static_cast<std::size_t>(std::count_if(
      items_.begin(), items_.end(), [](const Diagnostic& d) { return d.severity == Severity::Warning; }));
}

}  // namespace opencnc
