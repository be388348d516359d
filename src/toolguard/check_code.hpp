// SPDX-License-Identifier: GPL-3.0-or-later
// The tool guard's on-demand check as a user M-code module (M160 by default).
#pragma once

#include <memory>

#include "opencnc/gcode/extension.hpp"
#include "opencnc/store/tool_store.hpp"
#include "opencnc/tools/tool_check.hpp"

namespace opencnc::toolguard {

/// `M160`: checks the whole live tool table against the current backup where the interpreter
/// reads the block; a difference ends the program there with gcode.tool-guard-check naming each
/// one (in the preflight: the program is refused). Interpreter thread.
class CheckCode final : public gcode::CodeHandler {
 public:
  CheckCode(std::shared_ptr<store::ToolStore> store, const tools::CheckTolerances& tolerances)
      : store_(std::move(store)), tolerances_(tolerances) {}
  void execute(gcode::ExecContext& ctx, const gcode::Block& block, int code) override;

 private:
  std::shared_ptr<store::ToolStore> store_;
  tools::CheckTolerances tolerances_;
};

}  // namespace opencnc::toolguard
