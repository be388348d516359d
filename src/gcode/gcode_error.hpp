// SPDX-License-Identifier: GPL-3.0-or-later
// The exception the interpreter throws internally; converted to a Diagnostic at the API.
#pragma once

#include <exception>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "opencnc/gcode/error_codes.hpp"

namespace opencnc::gcode {

/// A G-code error: stable code, a message a person can act on, and (when known) the index
/// in the normalised block text where it was found (-1 = the whole block).
class GcodeError : public std::exception {
 public:
  GcodeError(ErrorCode code, std::string message, int position = -1)
      : code_(code), message_(std::move(message)), position_(position) {}
  const char* what() const noexcept override { return message_.c_str(); }
  ErrorCode code() const noexcept { return code_; }
  const std::string& message() const noexcept { return message_; }
  int position() const noexcept { return position_; }
  void set_position(int p) noexcept { position_ = p; }

 private:
  ErrorCode code_;
  std::string message_;
  int position_;
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
