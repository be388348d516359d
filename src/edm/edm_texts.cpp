// SPDX-License-Identifier: GPL-3.0-or-later
// The gap servo's event and fault in words, for the controller's event log.
#include "edm_texts.hpp"

#include <fmt/format.h>

namespace opencnc::edm {

std::optional<controller::EventNote> Texts::event_note(const control::ServoEvent& e,
                                                       const config::MachineProfile&,
                                                       const control::ServoConfig&) const {
  if (e.kind != control::EventKind::EdmRetractLimit) return std::nullopt;
  return controller::EventNote{
      Severity::Warning, "control.edm.retract-limit",
      fmt::format("EDM condition {}: backing off reached the end of the path memory {:.3f} mm behind "
                  "the program; the electrode holds there and can go back no further",
                  e.action, e.value)};
}

std::optional<std::string> Texts::fault_text(const control::Fault& f, const config::MachineProfile&,
                                             const control::ServoConfig&) const {
  if (f.kind != control::FaultKind::EdmShort) return std::nullopt;
  return fmt::format(
      "the EDM gap stayed shorted for {:.2f} s, longer than condition {}'s short_timeout_s ({} s): "
      "the program was stopped with the generator off; clear the gap (debris, a bridge, the electrode "
      "on the work) before going on",
      f.value, static_cast<int>(f.axis), f.limit);
}

}  // namespace opencnc::edm
