// SPDX-License-Identifier: GPL-3.0-or-later
// Broaching's events, waits and faults in words, for the controller's event log and status.
#include "texts.hpp"

#include <fmt/format.h>

namespace opencnc::broaching {

namespace {

char axis_letter(int axis) {
  return axis >= 0 && axis < kAxisCount ? kAxisLetters[static_cast<std::size_t>(axis)] : '?';
}

/// The load guard's message: what the load was, the level it passed, what the tick did.
std::string load_guard_text(const control::ServoEvent& e, const config::BroachingProfile& b) {
  const char axis = axis_letter(e.axis);
  switch (static_cast<control::LoadAction>(e.action)) {
    case control::LoadAction::Hold:
      return fmt::format(
          "broaching load {:.2f} kN above the hold level {:g} kN: feed hold (the coupling holds; "
          "check the cutter, then resume)",
          e.value, b.hold_kn);
    case control::LoadAction::Retract:
      return fmt::format(
          "broaching load {:.2f} kN above the retract level {:g} kN: the run stops on the helix "
          "and {} lifts the cutter by {:g} mm",
          e.value, b.retract_kn, axis, b.retract_lift);
    case control::LoadAction::Lifted:
      return fmt::format("the cutter is lifted ({} by {:g} mm); the run was stopped by an overload", axis,
                         b.retract_lift);
    case control::LoadAction::None:
      break;
  }
  return "load guard";
}

}  // namespace

std::optional<controller::EventNote> Texts::event_note(const control::ServoEvent& e,
                                                       const config::MachineProfile& profile,
                                                       const control::ServoConfig&) const {
  if (e.kind != control::EventKind::LoadGuard) return std::nullopt;
  return controller::EventNote{Severity::Warning, "control.load", load_guard_text(e, profile.broaching)};
}

std::optional<std::string> Texts::fault_text(const control::Fault& f, const config::MachineProfile&,
                                             const control::ServoConfig& servo) const {
  if (f.kind != control::FaultKind::CouplingPosition) return std::nullopt;
  const control::JointConfig* jc = nullptr;
  for (int j = 0; j < servo.joint_count; ++j)
    if (servo.joints[static_cast<std::size_t>(j)].axis == f.axis)
      jc = &servo.joints[static_cast<std::size_t>(j)];
  const char* unit = jc != nullptr && jc->rotary ? "deg" : "mm";
  return fmt::format(
      "the coupling code waited for {} to stand on its command, but it stayed {:.6f} {} off "
      "(within {:.6f} {} needed, [coupling] engage_tolerance_um, for engage_timeout_s): the drive "
      "does not settle; check its tuning, or allow more",
      axis_letter(f.axis), f.value, unit, f.limit, unit);
}

std::optional<std::string> Texts::wait_text(const control::ServoStatus& s) const {
  if (s.wait != control::Wait::Dwell || !s.coupling_wait) return std::nullopt;
  return "the coupled axes to stand on their commands before the law takes them (M171-M174)";
}

}  // namespace opencnc::broaching
