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

std::optional<std::string> Texts::fault_text(const control::Fault& f, const config::MachineProfile& profile,
                                             const control::ServoConfig&) const {
  if (f.kind == control::FaultKind::EdmFinishTimeout) {
    const machine::EdmCondition* c = profile.edm.config.find(static_cast<int>(f.axis));
    const double size = c != nullptr ? c->orbit_radius_mm : 0.0;
    const std::string reached =
        f.value >= size - 1e-9
            ? fmt::format("the orbit reached its {:.4f} mm but did not turn once there sparking", size)
            : fmt::format("the orbit reached {:.4f} mm of its {:.4f} mm", f.value, size);
    return fmt::format(
        "EDM condition {}'s finishing cycle did not bring the orbit to its size within its finish_timeout_s "
        "({} s): {} at the final depth; the program was stopped with the generator off and the cavity is "
        "undersize there (the gap kept the orbit from growing or turning: flushing, debris, the lateral servo's "
        "reference and gain); resume from the burn (run from line) or give the cycle more time",
        static_cast<int>(f.axis), f.limit, reached);
  }
  if (f.kind != control::FaultKind::EdmShort) return std::nullopt;
  return fmt::format(
      "the EDM gap stayed shorted for {:.2f} s, longer than condition {}'s short_timeout_s ({} s): "
      "the program was stopped with the generator off; clear the gap (debris, a bridge, the electrode "
      "on the work) before going on",
      f.value, static_cast<int>(f.axis), f.limit);
}

}  // namespace opencnc::edm
