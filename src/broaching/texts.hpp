// SPDX-License-Identifier: GPL-3.0-or-later
// The words of what broaching's stages of the tick raise: the load guard's actions, the coupling's
// wait for settled drives and its fault when they do not settle.
#pragma once

#include "opencnc/controller/extensions.hpp"

namespace opencnc::broaching {

/// The load guard's event (LoadGuard), the coupling's wait (a dwell while the coupled axes
/// settle) and fault (CouplingPosition) in words. Controller thread.
class Texts final : public controller::EventTexts {
 public:
  std::optional<controller::EventNote> event_note(const control::ServoEvent& e,
                                                  const config::MachineProfile& profile,
                                                  const control::ServoConfig& servo) const override;
  std::optional<std::string> fault_text(const control::Fault& f, const config::MachineProfile& profile,
                                        const control::ServoConfig& servo) const override;
  std::optional<std::string> wait_text(const control::ServoStatus& s) const override;
};

}  // namespace opencnc::broaching
