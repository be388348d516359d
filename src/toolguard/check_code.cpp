// SPDX-License-Identifier: GPL-3.0-or-later
// M160: the check on demand from G-code.
#include "check_code.hpp"

#include <fmt/format.h>

#include "opencnc/toolguard/tool_guard.hpp"

namespace opencnc::toolguard {

void CheckCode::execute(gcode::ExecContext& ctx, const gcode::Block& /*block*/, int code) {
  const CheckResult r = toolguard::check(*store_, tolerances_);
  if (!r.ok()) ctx.error(gcode::ErrorCode::ToolGuardCheck, fmt::format("M{}: {}", code, r.report()));
}

}  // namespace opencnc::toolguard
