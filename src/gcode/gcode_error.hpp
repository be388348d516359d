// SPDX-License-Identifier: GPL-3.0-or-later
// The exception the interpreter throws internally; converted to a Diagnostic at the API.
#pragma once

#include <cstdint>
#include <exception>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "opencnc/gcode/error_codes.hpp"

namespace opencnc::gcode {

/// A place in the program other than the current line (file index in the SourceMap,
/// 1-based line and column).
struct Where {
  std::uint32_t file = 0;
  std::uint32_t line = 0;
  std::uint32_t col = 0;
};

/// A G-code error: stable code, a message a person can act on, and (when known) the index
/// in the normalised block text where it was found (-1 = the whole block), or a place
/// elsewhere in the program that the error belongs to.
class GcodeError : public std::exception {
 public:
  GcodeError(ErrorCode code, std::string message, int position = -1,
             std::optional<Where> where = std::nullopt)
      : code_(code), message_(std::move(message)), position_(position), where_(where) {}
  const char* what() const noexcept override { return message_.c_str(); }
  ErrorCode code() const noexcept { return code_; }
  const std::string& message() const noexcept { return message_; }
  int position() const noexcept { return position_; }
  void set_position(int p) noexcept { position_ = p; }
  const std::optional<Where>& where() const noexcept { return where_; }

 private:
  ErrorCode code_;
  std::string message_;
  int position_;
  std::optional<Where> where_;
};

/// Throws a GcodeError with a formatted message.
template <typename... Args>
[[noreturn]] void fail(ErrorCode code, fmt::format_string<Args...> format, Args&&... args) {
  throw GcodeError(code, fmt::format(format, std::forward<Args>(args)...));
}

/// Same, at position `pos` of the normalised block text.
template <typename... Args>
[[noreturn]] void fail_at(int pos, ErrorCode code, fmt::format_string<Args...> format, Args&&... args) {
  throw GcodeError(code, fmt::format(format, std::forward<Args>(args)...), pos);
}

}  // namespace opencnc::gcode
