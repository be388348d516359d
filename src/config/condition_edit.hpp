// SPDX-License-Identifier: GPL-3.0-or-later
// A machining condition's key (`edm.condition.<number>.<field>`) edited in the profile's text:
// the condition's [[edm.condition]] element found by its number, its field's line changed.
#pragma once

#include <string>
#include <string_view>

#include "opencnc/config/profile_edit.hpp"

namespace opencnc::config::detail {

/// `text` (the profile `live` was loaded from) with the condition key `key` (lower case) set to
/// `value_toml`; `change` gets the key and its old value. False with `error` when the profile
/// has no such condition, or the line cannot be edited (then prefixed by the profile's file).
bool edit_condition(std::string& text, const MachineProfile& live, const std::string& key,
                    std::string_view value_toml, ProfileChange& change, std::string& error);

/// The value of the condition key `key` in `profile`, as condition_field_text() writes it.
std::string condition_value(const MachineProfile& profile, const std::string& key);

}  // namespace opencnc::config::detail
