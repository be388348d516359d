// SPDX-License-Identifier: GPL-3.0-or-later
// The audit's listing (audit_line.hpp).
#include "audit_line.hpp"

#include <fmt/format.h>

namespace opencnc::cli {

std::string audit_line(const store::AuditEntry& e, int reason_width, int what_width) {
  return fmt::format("{}  {:<12} {:<{}} {:<{}} {} -> {}\n", e.at_utc, e.interface, e.reason, reason_width,
                     e.what, what_width, e.old_value.empty() ? "(none)" : e.old_value,
                     e.new_value.empty() ? "(none)" : e.new_value);
}

}  // namespace opencnc::cli
