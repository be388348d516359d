// SPDX-License-Identifier: GPL-3.0-or-later
// Validation of numeric command-line options: NaN and infinities are refused (CLI::Range lets
// NaN through: every comparison with it is false).
#pragma once

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

namespace opencnc::cli {

/// A CLI11 check: the option's text is a finite number in [min, max]. CLI thread.
inline CLI::Validator finite_range(double min, double max) {
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0') return fmt::format("'{}' is not a number", text);
        if (!std::isfinite(v) || errno == ERANGE) return fmt::format("{} is not a finite number", text);
        if (v < min || v > max) return fmt::format("{} is outside [{:g}, {:g}]", text, min, max);
        return {};
      },
      fmt::format("NUMBER in [{:g}, {:g}]", min, max));
}

}  // namespace opencnc::cli
