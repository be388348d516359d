// SPDX-License-Identifier: GPL-3.0-or-later
// The words of what the gap servo raises: the end of its path memory, a short that stayed.
#pragma once

#include "opencnc/controller/extensions.hpp"

namespace opencnc::edm {

/// The gap servo's event (EdmRetractLimit) and fault (EdmShort) in words. Controller thread.
class Texts final : public controller::EventTexts {
 public:
  std::optional<controller::EventNote> event_note(const control::ServoEvent& e,
                                                  const config::MachineProfile& profile,
                                                  const control::ServoConfig& servo) const override;
  std::optional<std::string> fault_text(const control::Fault& f, const config::MachineProfile& profile,
                                        const control::ServoConfig& servo) const override;
};

}  // namespace opencnc::edm
