// SPDX-License-Identifier: GPL-3.0-or-later
// A program run on the simulated machine for the command line (`opencnc run`, `opencnc plot`):
// load the profile, home if needed, open, cycle start, follow the run to its end.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/canon/program.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/controller/controller.hpp"

namespace opencnc::cli {

struct SessionOptions {
  std::string file;
  std::string machine;
  std::vector<std::string> sets;
  bool realtime = false;  ///< a real-time periodic thread instead of virtual time
  /// Polled during the run: a signal number there stops it on the path (feed hold, then abort).
  const std::atomic<int>* stop = nullptr;
};

/// What a session ended with.
struct SessionEnd {
  int exit_code = 0;           ///< kExitOk, kExitProgram or kExitUsage
  bool finished = false;       ///< the program reached its end
  std::string fault;           ///< why it stopped early, in words ("" = it did not)
  bool limit_touched = false;  ///< a soft limit or a limit switch stopped it
  int stopped_by = 0;          ///< the signal that stopped it (SessionOptions::stop), 0 if none
  double wall_s = 0;           ///< wall-clock time of the run
  std::shared_ptr<const canon::Program> program;
  config::MachineProfile profile;
};

/// Called once the program is open (before it starts), for every servo period of the run, and
/// now and then with the status (for progress).
struct SessionHooks {
  std::function<void(const config::MachineProfile&, const canon::Program&)> opened;
  std::function<void(const control::TraceSample&)> sample;
  std::function<void(const control::ControllerStatus&, double elapsed_wall_s)> progress;
};

/// Runs `o.file` on the simulated machine of `o.machine`; prints problems to stderr. Program
/// stops (M0, M1) and manual tool changes are continued at once (there is no operator).
SessionEnd run_session(const SessionOptions& o, const SessionHooks& hooks);

}  // namespace opencnc::cli
