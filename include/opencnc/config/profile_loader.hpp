// SPDX-License-Identifier: GPL-3.0-or-later
// Loading a machine profile from TOML, with `--set key=value` overrides and validation.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::config {

/// The outcome of a load: the profile if there was no error, and every error and warning
/// found (`file:line:col: message`, with stable codes `config.*`; see docs/machine.md).
struct ProfileLoad {
  std::optional<MachineProfile> profile;
  Diagnostics diagnostics;
  bool ok() const noexcept { return profile.has_value(); }
};

/// A file's text that stands in for the file on disk while a profile is parsed (an edit checked
/// by the loader before it is written). `path` as the loader resolves it (the profile's folder
/// joined with the name the profile gives).
struct FileText {
  std::string path;
  std::string text;
};

/// Reads, overrides and validates the profile in `file`. Each override is `dotted.key=value`
/// with a TOML value (a bare word is taken as a string), applied before validation and
/// validated the same way; its diagnostics name the file `--set` and the line is the
/// override's number (1 = first). Relative paths in the profile are resolved against the
/// file's folder. Non-real-time; does not throw.
ProfileLoad load_profile(const std::filesystem::path& file, std::span<const std::string> overrides = {});

/// The same for profile text already in memory; `source_name` names it in diagnostics and
/// relative paths are resolved against `base_dir`. A file the profile names (a comp file) whose
/// path is among `files` is read from there, not from the disk. Non-real-time; does not throw.
ProfileLoad parse_profile(std::string_view text, std::string_view source_name,
                          std::span<const std::string> overrides = {},
                          const std::filesystem::path& base_dir = {}, std::span<const FileText> files = {});

/// The digest of a profile's text that MachineProfile::source_digest holds (FNV-1a, 64 bits).
/// Any thread.
std::uint64_t text_digest(std::string_view text) noexcept;

}  // namespace opencnc::config
