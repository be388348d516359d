// SPDX-License-Identifier: GPL-3.0-or-later
// StreamTickets — short-lived, single-use tickets that open the status stream, so that a browser
// (which cannot give a WebSocket headers) never puts its token in a URL.
#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

#include "opencnc/hmi/api.hpp"

namespace opencnc::hmi {

/// Tickets issued to a holder of a token, each redeemed once for that token's role within its
/// lifetime. Any thread (a mutex inside); not real-time.
class StreamTickets {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::seconds kLifetime{30};
  static constexpr std::size_t kMaxOutstanding = 1024;  ///< the oldest go when more are asked for

  /// A new ticket for `role`, valid until now + kLifetime; nothing (and `*error`) without random
  /// numbers.
  std::optional<std::string> issue(Role role, Clock::time_point now, std::string* error);
  /// The role of `ticket` when it was issued, is unused and unexpired; it is used up either way.
  std::optional<Role> redeem(const std::string& ticket, Clock::time_point now);
  /// Tickets issued and not yet redeemed or expired (as of the last call).
  std::size_t outstanding() const;

 private:
  struct Entry {
    Role role;
    Clock::time_point expires;
  };
  void expire(Clock::time_point now);

  mutable std::mutex mutex_;
  std::unordered_map<std::string, Entry> tickets_;
};

}  // namespace opencnc::hmi
