// SPDX-License-Identifier: GPL-3.0-or-later
// The audit's listing of `opencnc tools audit` and `opencnc cutchart audit`.
#pragma once

#include <string>

#include "opencnc/store/tool_store.hpp"

namespace opencnc::cli {

/// One audited change on a line of its own: when, interface, reason, what, old -> new ("(none)"
/// for a value that was not there), the reason and what in columns of the given widths.
std::string audit_line(const store::AuditEntry& e, int reason_width, int what_width);

}  // namespace opencnc::cli
