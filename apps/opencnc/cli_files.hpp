// SPDX-License-Identifier: GPL-3.0-or-later
// The files a subcommand reads and writes, checked before it runs (outputs: core::OutputFile's rules).
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/core/output_file.hpp"

namespace opencnc::cli {

struct SessionOptions;

/// The session's profile with its overrides, read quietly: nullopt if it has errors (the run
/// reports them itself). CLI thread.
std::optional<config::MachineProfile> quiet_profile(const SessionOptions& o);

/// The files a run reads: the program, the profile and the tool table `profile` names (if
/// given). CLI thread.
std::vector<NamedPath> session_inputs(const SessionOptions& o, const config::MachineProfile* profile);

/// Says (on stderr) which input cannot be read and why — missing, unreadable (`strerror`), a
/// folder — and returns false; true if every non-empty path can be read. CLI thread.
bool check_inputs(std::span<const NamedPath> inputs);

/// Opens every output whose path is not empty, after checking that none names an input or
/// another output. Returns one entry per output (nullptr for an empty path), or an empty
/// vector after printing the problem (nothing was created). CLI thread.
std::vector<std::unique_ptr<OutputFile>> open_outputs(std::span<const NamedPath> inputs,
                                                      std::span<const NamedPath> outputs);

/// Commits `out`; prints the problem and returns false. CLI thread.
bool commit(OutputFile& out);
/// Writes `content` as one record and commits; prints the problem and returns false.
/// CLI thread.
bool write_and_commit(OutputFile& out, std::string_view content);

/// Replaces the profile file `path` by `text` (a measurement written into it): never
/// half-written (a temporary file renamed over it, its permissions kept), and not when the file
/// is not a regular one we may write or no longer holds `original` (the text measured from).
/// False with `why` otherwise. CLI thread.
bool replace_profile_text(const std::string& path, const std::string& original, const std::string& text,
                          std::string& why);

}  // namespace opencnc::cli
