// SPDX-License-Identifier: GPL-3.0-or-later
// RunFeature — a machine feature's part of `opencnc run`: its options, what it checks before
// anything runs, what it adds to the session (injected faults, a scripted operator, the operator's
// answers where it holds the program, observers) and its lines of the report. `opencnc run` is a
// loop over them (run_features()), in the order features::set_up sets the features up.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_files.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/machine_setup.hpp"
#include "run_session.hpp"

namespace opencnc::machine {
class SimMachine;
}

namespace opencnc::cli {

/// What a feature's injectable fault looks like (`--inject FORM`), for the option's help and its
/// error message.
struct InjectionForm {
  std::string form;  ///< "tool-dull@SECONDS=FACTOR"
  std::string help;  ///< what it does, for the option's help ("the broach's cutter wears: …")
  std::string note;  ///< what its numbers must be, for the error ("0 < FACTOR <= 100, …"), or ""
};

/// One feature's part of `opencnc run`. Every call comes from the command line's one thread.
class RunFeature {
 public:
  virtual ~RunFeature() = default;
  /// Adds its options to `run`.
  virtual void add_options(CLI::App& /*run*/) {}
  /// The faults it injects (`--inject`).
  virtual std::vector<InjectionForm> injections() const { return {}; }
  /// `text` (an --inject value) if it is one of this feature's: true when it is (`ok` false after
  /// printing why it is malformed).
  virtual bool parse_injection(const std::string& /*text*/, bool& /*ok*/) { return false; }
  /// Before any file is opened: its options on their own (a file name's form). False after
  /// printing why.
  virtual bool check_options() { return true; }
  /// The files it writes, named by their option (opened with the run's others before anything
  /// runs: none over an input or another output).
  virtual std::vector<NamedPath> outputs() const { return {}; }
  /// Its files as opened (null for an empty name), in outputs()'s order.
  virtual void take_outputs(const std::vector<OutputFile*>& /*files*/) {}
  /// Before anything runs: its options against the profile (null: not readable yet, the session
  /// says why) and the session; it may ask things of the session (a tool table in memory, a
  /// setting for its setup). False after printing why.
  virtual bool check(const config::MachineProfile* /*profile*/, SessionOptions& /*session*/) { return true; }
  /// The machine's features are set up: it takes the ones it drives (its own and their
  /// observers). False after printing why.
  virtual bool set_up(controller::MachineSetup& /*machine*/) { return true; }
  /// The program is open and checked: observers for its run.
  virtual void opened(const config::MachineProfile& /*machine*/, SessionObservers& /*out*/) {}
  /// Every period of the run (in virtual time with the simulated machine, else null).
  virtual void tick(controller::Controller& /*c*/, const controller::ControllerStatus& /*st*/,
                    machine::SimMachine* /*sim*/) {}
  /// An event of the run: the operator's answer where the feature holds the program. False when
  /// the run was aborted.
  virtual bool on_event(const controller::ControllerEvent& /*e*/, SessionOperator& /*op*/) { return true; }
  /// The program's job ended: true when the session goes on with the job that resumes it.
  virtual bool goes_on(const controller::ControllerEvent& /*e*/) const { return false; }
  /// The session ends: what it keeps of the simulated machine (virtual time; else null).
  virtual void finished(machine::SimMachine* /*sim*/) {}
  /// Its lines of the report on stdout and its part of the report's JSON; false when something
  /// it writes failed (after printing why).
  virtual bool report(nlohmann::json& /*j*/) { return true; }
};

/// The features' parts of `opencnc run`, in the order features::set_up sets the features up: the
/// tool guard, broaching, the EDM, retrace, the process log.
std::vector<std::unique_ptr<RunFeature>> run_features();

}  // namespace opencnc::cli
