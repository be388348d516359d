// SPDX-License-Identifier: GPL-3.0-or-later
// A machining condition's key (`edm.condition.<number>.<field>`) edited in the profile's text (the
// condition's [[edm.condition]] element found by its number, its field's line changed), and whole
// conditions added or deleted there.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/config/profile_edit.hpp"

namespace opencnc::config::detail {

/// `text` (the profile `live` was loaded from) with the condition key `key` (lower case) set to
/// `value_toml`; `change` gets the key and its old value. False with `error` when the profile
/// has no such condition, or the line cannot be edited (then prefixed by the profile's file).
bool edit_condition(std::string& text, const MachineProfile& live, const std::string& key,
                    std::string_view value_toml, ProfileChange& change, std::string& error);

/// `text` with the conditions `changes` made (adds appended in order, then deletes), counted
/// against `live`'s conditions; `changes_out` gets one line each ("edm.condition.7" "none" →
/// "a copy of condition 3"). False with `error` (prefixed by the profile's file) when one cannot
/// be made (ConditionChange's rules in edit_profile()).
bool change_conditions(std::string& text, const MachineProfile& live,
                       std::span<const ConditionChange> changes, std::span<const ProfileKeyEdit> edits,
                       std::vector<ProfileChange>& changes_out, std::string& error);

/// The value of the condition key `key` in `profile`, as condition_field_text() writes it.
std::string condition_value(const MachineProfile& profile, const std::string& key);

}  // namespace opencnc::config::detail
