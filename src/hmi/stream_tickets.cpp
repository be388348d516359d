// SPDX-License-Identifier: GPL-3.0-or-later
// StreamTickets: random single-use tickets with a lifetime, for opening the status stream.
#include "opencnc/hmi/stream_tickets.hpp"

#include <algorithm>

#include "opencnc/hmi/tokens.hpp"

namespace opencnc::hmi {

std::optional<std::string> StreamTickets::issue(Role role, Clock::time_point now, std::string* error) {
  std::optional<std::string> t = random_secret(error);
  if (!t) return std::nullopt;
  std::lock_guard lock(mutex_);
  expire(now);
  if (tickets_.size() >= kMaxOutstanding) {
    // The one that expires first goes (a client that asks for tickets and never uses them).
    const auto oldest = std::min_element(tickets_.begin(), tickets_.end(), [](const auto& a, const auto& b) {
      return a.second.expires < b.second.expires;
    });
    tickets_.erase(oldest);
  }
  tickets_.emplace(*t, Entry{role, now + kLifetime});
  return t;
}

std::optional<Role> StreamTickets::redeem(const std::string& ticket, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  expire(now);
  const auto it = tickets_.find(ticket);
  if (it == tickets_.end()) return std::nullopt;
  const Role role = it->second.role;
  tickets_.erase(it);
  return role;
}

std::size_t StreamTickets::outstanding() const {
  std::lock_guard lock(mutex_);
  return tickets_.size();
}

void StreamTickets::expire(Clock::time_point now) {
  std::erase_if(tickets_, [now](const auto& e) { return e.second.expires <= now; });
}

}  // namespace opencnc::hmi
