// SPDX-License-Identifier: GPL-3.0-or-later
// Running a program as a subprocess with its output captured and a time limit.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace opencnc::conformance {

/// The outcome of a subprocess.
struct ProcessResult {
  int exit_status = -1;     ///< the exit code, or 128 + signal number when killed by a signal
  bool timed_out = false;   ///< killed because it ran over the time limit
  std::string out;          ///< standard output
  std::string err;          ///< standard error
  std::string error;        ///< why it could not be started (then exit_status is -1)
};

/// Runs `argv` (argv[0] is looked up on PATH when it has no '/') in `cwd`, with standard input
/// from /dev/null and this process's environment changed by `env` ("KEY=VALUE" entries), and
/// waits for it at most `timeout_s` seconds. Test code; any thread.
ProcessResult run_process(const std::vector<std::string>& argv, const std::filesystem::path& cwd,
                          double timeout_s, const std::vector<std::string>& env = {});

/// The full path of `program` found on PATH, or empty.
std::filesystem::path find_on_path(const std::string& program);

}  // namespace opencnc::conformance
