// SPDX-License-Identifier: GPL-3.0-or-later
// Golden files of the conformance suite: rs274's exit status, error text and listing.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace opencnc::conformance {

/// What rs274 did with one program (see regen-golden.sh for the file format).
struct Golden {
  int exit_status = 0;
  std::vector<std::string> stderr_lines;  ///< without rs274's "executing" line
  std::string listing;                    ///< standard output, unchanged

  /// rs274's error message (the first stderr line), empty when it accepted the program.
  std::string message() const { return stderr_lines.empty() ? std::string{} : stderr_lines.front(); }
};

/// Reads a whole file; `.xz` files are decompressed. Throws std::runtime_error on failure.
std::string read_file(const std::filesystem::path& path);

/// Parses a golden file's text. Throws std::runtime_error when the header is malformed.
Golden parse_golden(const std::string& text);

/// Reads and parses a golden file.
Golden load_golden(const std::filesystem::path& path);

}  // namespace opencnc::conformance
