// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI's access tokens: an operator and an admin token, from the environment or generated at
// first start into a file only its owner may read.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "opencnc/hmi/api.hpp"

namespace opencnc::hmi {

/// The two tokens and where they came from. Immutable after load; any thread reads it.
class Tokens {
 public:
  /// OPENCNC_OPERATOR_TOKEN and OPENCNC_ADMIN_TOKEN when both are set (at least 16 characters
  /// each); otherwise the file `path`: read when it exists (refused when others may read it or it
  /// is malformed), else written with two new random tokens, mode 0600, crash-safe. Nothing
  /// (and `*error`) on failure. Non-real-time.
  static std::optional<Tokens> load(const std::filesystem::path& path, std::string* error);
  /// Two given tokens (tests). Any thread.
  static Tokens of(std::string operator_token, std::string admin_token);

  /// The role a presented token has; nothing for a wrong or empty one (compared in constant
  /// time). Any thread.
  std::optional<Role> role_of(std::string_view token) const noexcept;
  const std::string& operator_token() const noexcept { return operator_; }
  const std::string& admin_token() const noexcept { return admin_; }
  /// "environment", or the file's path. Any thread.
  const std::string& origin() const noexcept { return origin_; }

 private:
  std::string operator_, admin_, origin_;
};

/// 24 random bytes from the kernel as 48 hex digits (nothing, and `*error`, when none come).
/// Any thread.
std::optional<std::string> random_secret(std::string* error);

}  // namespace opencnc::hmi
