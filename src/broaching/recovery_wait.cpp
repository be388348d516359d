// SPDX-License-Identifier: GPL-3.0-or-later
// run_recovery: the bounded wait for a recovery choice on the simulated machine.
#include "opencnc/broaching/recovery_wait.hpp"

#include <fmt/format.h>

namespace opencnc::recovery {

namespace {

bool ended(RecoveryPhase p) {
  return p == RecoveryPhase::Done || p == RecoveryPhase::Failed;
}

}  // namespace

std::string run_recovery(controller::SimRig& rig, const BreakpointJournal& journal, RecoveryWait wait) {
  const double period_s = rig.controller().profile().servo_period_s;
  const auto periods = [&](double s) { return static_cast<std::uint64_t>(s / period_s) + 1; };
  std::string why;
  std::uint64_t idle = 0;
  const std::uint64_t stall = periods(wait.stall_s);
  bool aborted = false;
  rig.run_until(
      [&] {
        if (ended(journal.phase())) return true;
        const controller::ControllerStatus st = rig.status();
        idle = st.run_active ? 0 : idle + 1;
        if (idle >= stall) {
          why = fmt::format("no job ran for {} s and the choice did not end", wait.stall_s);
          return true;
        }
        if (!aborted &&
            (st.servo.state == control::State::Held || st.servo.state == control::State::Faulted)) {
          why = st.servo.state == control::State::Held
                    ? fmt::format("the feed was held (load {:.3f} kN) and nobody resumes it here: aborted",
                                  st.servo.load_kn)
                    : "a fault stopped it: " + st.fault_text;
          if (st.servo.state == control::State::Held)
            rig.controller().submit(controller::Request::simple(control::CommandKind::Abort));
          aborted = true;
        }
        return false;
      },
      periods(wait.max_s));
  if (journal.phase() == RecoveryPhase::Done) return {};
  if (why.empty())
    why = ended(journal.phase()) ? journal.recovery_error()
                                 : fmt::format("not ended after {} s of machine time", wait.max_s);
  else if (!journal.recovery_error().empty())
    why += " (" + journal.recovery_error() + ")";
  return why;
}

}  // namespace opencnc::recovery
