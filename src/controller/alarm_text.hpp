// SPDX-License-Identifier: GPL-3.0-or-later
// Process alarms in words: what tripped, the reading and the bound, what the machine did.
#pragma once

#include <string>

#include "opencnc/config/machine_profile.hpp"

namespace opencnc::controller::detail {

/// "alarm dielectric_level: input 0 reads 12.30 %, below its low bound of 20 %: feed hold", or
/// "… is back in range (45.00 %)" when `cleared`. Controller thread.
std::string alarm_text(const config::AlarmProfile& alarms, std::size_t index, double value, bool low,
                       bool cleared);

}  // namespace opencnc::controller::detail
