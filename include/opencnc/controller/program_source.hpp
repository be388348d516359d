// SPDX-License-Identifier: GPL-3.0-or-later
// ProgramSource — the seam between G-code (files and MDI lines) and the controller: whatever
// turns text into a canon::Program in machine coordinates.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "opencnc/canon/program.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::control {

/// A program, or the reasons there is none (`file:line:col: message` with codes).
struct LoadedProgram {
  std::shared_ptr<const canon::Program> program;  ///< null when there were errors
  Diagnostics diagnostics;
};

/// Switches that change how a program is read.
struct LoadOptions {
  bool block_delete = false;  ///< skip lines that start with '/'
};

/// Turns G-code into canonical programs. The controller calls it from its own thread (non-real-
/// time); implementations need not be thread-safe.
class ProgramSource {
 public:
  virtual ~ProgramSource() = default;
  /// A program file, its first move starting at `start` (machine coordinates).
  virtual LoadedProgram load(const std::string& path, const Pose& start, const LoadOptions& options) = 0;
  /// One MDI line, starting at `start`, continuing the modal state the earlier lines left.
  virtual LoadedProgram mdi(std::string_view line, const Pose& start) = 0;
};

}  // namespace opencnc::control
