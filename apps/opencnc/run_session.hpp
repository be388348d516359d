// SPDX-License-Identifier: GPL-3.0-or-later
// A program run on the simulated machine for the command line (`opencnc run`, `opencnc plot`):
// load the profile, home if needed, open, cycle start, follow the run to its end, with the
// operator at the terminal where the program waits for one.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/status.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/machine_setup.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::machine {
class SimMachine;
}

namespace opencnc::cli {

struct SessionOptions {
  std::string file;
  std::string machine;
  std::vector<std::string> sets;
  bool realtime = false;    ///< a real-time periodic thread instead of virtual time
  /// The tick runs in LinuxCNC's HAL (opencnc_rt.so): attach to its shared memory `hal_shm`
  /// instead of ticking here. docs/hal.md.
  bool hal = false;
  std::string hal_shm = "/opencnc";
  bool unattended = false;  ///< continue program stops and manual tool changes without asking
  /// Polled during the run: a signal number there stops it on the path (feed hold, then abort).
  const std::atomic<int>* stop = nullptr;
  /// Polled with `stop`: how many signals came; from the second on the run is aborted at once
  /// (the report is still written).
  const std::atomic<int>* stops = nullptr;
  /// Machine time (s) after which the run is stopped on the path as by a signal (0: none):
  /// `run --max-time` holds while the program runs, not only in its estimate.
  double max_time_s = 0;
  /// Virtual time: the simulated mains fail at this servo time (s); negative: never.
  double mains_off_s = -1;
  /// Virtual time: a simulated analog input driven to `value` from servo time `at_s`, over `ramp_s`
  /// (0: at once) — a process input (dielectric level, a temperature) drifting out of range.
  struct AnalogInjection {
    int channel = 0;
    double value = 0, at_s = 0, ramp_s = 0;
  };
  std::optional<AnalogInjection> analog;
  /// The program's tool table is a copy in memory: what the run changes in it (a simulated
  /// electrode's measurement, `run --electrode-change`) does not reach the profile's file.
  bool tool_table_in_memory = false;
  /// The run writes a report: the features add the observers of its sections.
  bool reports = false;
  /// Settings for the features' setup by name (controller::MachineSetup::Options): "journal".
  std::map<std::string, std::string, std::less<>> settings;
};

/// What a session ended with.
struct SessionEnd {
  int exit_code = 0;           ///< kExitOk, kExitProgram or kExitUsage
  bool finished = false;       ///< the program reached its end
  std::string fault;           ///< why it stopped early, in words ("" = it did not)
  bool limit_touched = false;  ///< a soft limit or a limit switch stopped it
  int stopped_by = 0;          ///< the signal that stopped it (SessionOptions::stop), 0 if none
  bool over_max_time = false;  ///< SessionOptions::max_time_s stopped it
  double wall_s = 0;           ///< wall-clock time of the run
  config::MachineProfile profile;
  std::optional<controller::OpenProgram> program;  ///< the program as opened (its preflight)
};

/// Observers to attach for a run, with their options.
using SessionObservers =
    std::vector<std::pair<std::shared_ptr<controller::ControllerObserver>, controller::ObserverOptions>>;

/// The operator at the terminal, for a feature that holds the program and asks (the tool guard's
/// accept or restore, the load guard's resume). Controller thread (the session's loop).
class SessionOperator {
 public:
  virtual ~SessionOperator() = default;
  /// Prints `question` and waits for a line, the machine going on meanwhile; nothing when no one
  /// can answer (--unattended, stdin closed).
  virtual std::optional<std::string> ask(const std::string& question) = 0;
  /// Sends a request and waits for its answer (printing a refusal); whether it was accepted.
  virtual bool must(controller::Request r) = 0;
  /// Sends a request.
  virtual void submit(controller::Request r) = 0;
};

/// Observers attached before the program starts (a run recorder, a trace writer), and progress.
struct SessionHooks {
  /// Called once the program is open and checked, before it starts: return the observers to
  /// attach (with their options) for the run.
  std::function<SessionObservers(const config::MachineProfile&, const controller::OpenProgram&)> opened;
  /// Called once the program is open and checked, before `opened`: false ends the session there
  /// (nothing has moved; it has said why). A program the preflight refused never gets here, so a
  /// second look at it (the machining time against --max-time) is made only of a finite program.
  std::function<bool(const config::MachineProfile&, const controller::OpenProgram&)> may_start;
  /// Now and then with the status (for progress).
  std::function<void(const controller::ControllerStatus&, double elapsed_wall_s)> progress;
  /// Once the machine's features are set up (features::set_up), before the controller is built:
  /// the command line takes the features it drives. False stops the session (after printing why).
  std::function<bool(controller::MachineSetup&)> set_up;
  /// Every period of the run, with the controller and (in virtual time, else null) the simulated
  /// machine: a scripted operator (`run --retrace`, `run --electrode-change`).
  std::function<void(controller::Controller&, const controller::ControllerStatus&, machine::SimMachine*)>
      tick;
  /// When the program's job ends: true if the session goes on with the job that resumes it.
  std::function<bool(const controller::ControllerEvent&)> goes_on;
  /// Every event of the run, after it is printed: a feature that holds the program asks the
  /// operator (and aborts when no one answers).
  std::function<void(const controller::ControllerEvent&, SessionOperator&)> on_event;
  /// The session ends, with the simulated machine (virtual time; else null): what the features
  /// keep of it (the simulated bore, the spark gap's figures).
  std::function<void(machine::SimMachine*)> finished;
};

/// Runs `o.file` on the simulated machine of `o.machine`; prints problems and program messages
/// to stderr. At program stops (M0, M1) and manual tool changes it asks the operator on the
/// terminal (stdin: Enter continues, `a` aborts), or continues at once when `o.unattended`. A
/// hand-fed axis is brought where the program waits for it by the simulated machine's hand.
SessionEnd run_session(const SessionOptions& o, const SessionHooks& hooks);

}  // namespace opencnc::cli
