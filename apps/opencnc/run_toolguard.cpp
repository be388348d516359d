// SPDX-License-Identifier: GPL-3.0-or-later
// The tool guard's part of `opencnc run`: the operator's answer where it holds the program.
#include <fmt/format.h>

#include "run_features_parts.hpp"

namespace opencnc::cli {

namespace {

using control::CommandKind;
using controller::Request;

// The tool guard holds the program before a tool cuts (its note, with the differences, is
// printed): the operator at the terminal accepts the live values or restores the backup, and the
// program goes on; anything else, --unattended or no terminal aborts it (nothing is ever accepted
// without the operator).
class ToolGuardRun final : public RunFeature {
 public:
  bool on_event(const controller::ControllerEvent& e, SessionOperator& op) override {
    if (e.kind != controller::ControllerEventKind::Note || e.code != "tools.guard-hold" || aborted_)
      return true;
    const std::optional<std::string> answer = op.ask(
        "the tool guard holds the program: type accept (the live values become the backup) or restore (the "
        "backup's values become live) and Enter; anything else aborts");
    if (answer && (*answer == "accept" || *answer == "restore") &&
        op.must(Request::feature("tool-guard", *answer)))
      return true;
    fmt::print(
        stderr,
        "error: the tool guard holds the program before the tool cuts; it is aborted: accept or restore "
        "(`opencnc tools --db STORE accept|restore`, or at the terminal without --unattended), then run "
        "it again\n");
    op.submit(Request::simple(CommandKind::Abort));
    aborted_ = true;
    return false;
  }

 private:
  bool aborted_ = false;
};

}  // namespace

std::unique_ptr<RunFeature> toolguard_run() {
  return std::make_unique<ToolGuardRun>();
}

}  // namespace opencnc::cli
