// SPDX-License-Identifier: GPL-3.0-or-later
// Writing a measured compensation table into a machine profile's text, everything else kept as
// the user wrote it.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/core/axes.hpp"

namespace opencnc::config {

/// `[axis.<letter>.compensation]` holding `c` (its positions at equal intervals from start),
/// as TOML text ending in a newline. Any thread.
std::string compensation_toml(Axis axis, const CompensationProfile& c);

/// `text` (a profile) with the `[axis.<letter>.compensation]` table replaced by `c`, or added after
/// the axis' last table when it has none. Comments and blank lines that lead into the next table
/// stay; the old table's own lines go. The result is checked: it must parse, hold exactly `c` for
/// that axis, and be the same TOML as `text` in everything else. Returns nullopt and sets `error`
/// when the text cannot be edited so (no `[axis.<letter>]` table of its own, the compensation
/// written inline, a table that does not come back as written). Non-real-time.
std::optional<std::string> with_compensation(std::string_view text, Axis axis, const CompensationProfile& c,
                                             std::string& error);

}  // namespace opencnc::config
