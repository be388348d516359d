// SPDX-License-Identifier: GPL-3.0-or-later
// `--set dotted.key=value` overrides merged into a parsed profile before validation.
#pragma once

#include <toml++/toml.h>

#include <span>
#include <string>

#include "toml_reader.hpp"

namespace opencnc::config::detail {

/// Merges each override into `root`, replacing values and adding keys. The values keep
/// their source position: file "--set", line = the override's number, column within it, so
/// that validation reports a bad override where it was written. Reports overrides that are
/// not `key=value` TOML; returns false if there was one.
bool apply_overrides(toml::table& root, std::span<const std::string> overrides, Reporter& reporter);

}  // namespace opencnc::config::detail
