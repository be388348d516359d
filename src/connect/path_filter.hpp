// SPDX-License-Identifier: GPL-3.0-or-later
// connect::select_items — the data items an MTConnect `path=` XPath selects in the device model.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/connect/device_model.hpp"

namespace opencnc::connect {

/// The items `xpath` selects (a DataItem, or every DataItem under a selected component), as a flag
/// per item; or the reason it selects none in `error`. The expression sees the probe document's
/// elements without their namespace (`//Axes//DataItem[@type="POSITION"]`), as MTConnect agents do.
std::optional<std::vector<bool>> select_items(const DeviceModel& model, std::string_view xpath,
                                              std::string* error);

}  // namespace opencnc::connect
