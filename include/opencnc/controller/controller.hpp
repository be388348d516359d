// SPDX-License-Identifier: GPL-3.0-or-later
// control::Controller — the non-real-time half of the controller and the one API of every front
// end: requests in (thread-safe), status snapshots and outcomes out. It loads and checks
// programs, runs MDI lines, feeds the planner into the servo's block queue, and turns what the
// servo reports into words.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "opencnc/canon/program.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/channels.hpp"
#include "opencnc/control/command.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/plan/planner.hpp"

namespace opencnc::control {

/// What a front end asks for: a command, plus what only this side can carry (a file name, a
/// G-code line, a program). Build one with the helpers below.
struct Request {
  CommandKind kind = CommandKind::Abort;
  Mode mode = Mode::Manual;
  int axis = -1;  ///< Axis index (X = 0 …), −1 = all / none
  bool flag = false;
  double value = 0, value2 = 0;
  std::string text;                               ///< OpenProgram: the file; Mdi: the line
  std::shared_ptr<const canon::Program> program;  ///< OpenProgram without a file

  static Request simple(CommandKind k) {
    Request r;
    r.kind = k;
    return r;
  }
  static Request set_mode(Mode m) {
    Request r = simple(CommandKind::SetMode);
    r.mode = m;
    return r;
  }
  /// Continuous jog at `velocity` (signed, units/s).
  static Request jog(Axis a, double velocity) {
    Request r = simple(CommandKind::JogContinuous);
    r.axis = index(a);
    r.value = velocity;
    return r;
  }
  /// Incremental jog by `distance` (signed) at `speed`.
  static Request jog_by(Axis a, double distance, double speed) {
    Request r = simple(CommandKind::JogIncrement);
    r.axis = index(a);
    r.value = distance;
    r.value2 = speed;
    return r;
  }
  static Request on_axis(CommandKind k, int axis) {
    Request r = simple(k);
    r.axis = axis;
    return r;
  }
  static Request open(std::string path) {
    Request r = simple(CommandKind::OpenProgram);
    r.text = std::move(path);
    return r;
  }
  static Request open(std::shared_ptr<const canon::Program> p, std::string name) {
    Request r = simple(CommandKind::OpenProgram);
    r.program = std::move(p);
    r.text = std::move(name);
    return r;
  }
  static Request mdi(std::string line) {
    Request r = simple(CommandKind::Mdi);
    r.text = std::move(line);
    return r;
  }
  static Request value_of(CommandKind k, double v) {
    Request r = simple(k);
    r.value = v;
    return r;
  }
  static Request flag_of(CommandKind k, bool on) {
    Request r = simple(k);
    r.flag = on;
    return r;
  }
};

/// The answer to a request.
struct Outcome {
  bool accepted = false;
  Refusal refusal = Refusal::None;
  std::string message;      ///< why it was refused, in words
  Diagnostics diagnostics;  ///< program problems (OpenProgram, Mdi, CycleStart)
};

/// Something the operator should read: a program message (MSG), a fault, a refused program.
struct Note {
  std::uint64_t tick = 0;
  Severity severity = Severity::Note;
  std::string code;  ///< stable code (control.fault.*, control.*), empty for program messages
  std::string text;
};

/// The status a front end shows: the servo's snapshot plus what this side knows.
struct ControllerStatus {
  ServoStatus servo;
  std::string program_name;  ///< the open program ("" = none)
  std::uint64_t program_moves = 0;
  bool run_active = false;          ///< a run was started and has not ended
  std::uint64_t run_segment = 0;    ///< segment of the open program at the commanded position
  double progress = 0;              ///< 0 … 1 of the open program's moves
  std::string fault_text;           ///< servo.fault in words ("" = none)
  std::uint64_t runs_finished = 0;  ///< runs that reached their program end
};

/// The non-real-time half of the controller. `submit()`, `status()`, `outcome()` and
/// `take_notes()` may be called from any thread; `service()` from one thread only (the
/// controller's, or the driver of virtual time between ticks). Nothing here is real-time.
class Controller {
 public:
  /// `channels` must outlive the controller; `source` turns G-code into programs (may be null:
  /// then only programs given as canon::Program can run).
  Controller(const config::MachineProfile& profile, ServoChannels& channels,
             std::shared_ptr<ProgramSource> source = nullptr);
  ~Controller();
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  /// Queues a request; returns its id (the answer comes as its Outcome). Any thread.
  std::uint64_t submit(Request r);
  /// The answer to request `id`, once known. Any thread.
  std::optional<Outcome> outcome(std::uint64_t id) const;
  /// The newest status. Any thread.
  ControllerStatus status() const;
  /// Notes since the last call. Any thread.
  std::vector<Note> take_notes();
  /// The program the open program came from (null = none). Any thread.
  std::shared_ptr<const canon::Program> open_program() const;

  /// The periodic work: reads the servo's events and status, handles queued requests, keeps
  /// the planner ahead of the servo. Controller thread. Deterministic for the same inputs.
  void service();

  const ServoConfig& servo_config() const noexcept { return servo_config_; }

 private:
  struct Run;
  void read_servo();
  void on_event(const ServoEvent& e);
  void handle(std::uint64_t id, Request& r);
  void open(std::uint64_t id, Request& r);
  void mdi(std::uint64_t id, const Request& r);
  void cycle_start(std::uint64_t id, const Request& r);
  void start_run(std::uint64_t id, std::shared_ptr<const canon::Program> program, Mode mode,
                 canon::SegmentId segment_offset);
  /// Soft-limit preflight and the planner's own checks; the started planner, or null.
  std::unique_ptr<plan::Planner> prepare(const canon::Program& program, Diagnostics& diags) const;
  void forward(std::uint64_t id, const Request& r, const Command& extra = {});
  void pump();
  void continue_after_probe();
  void finish(std::uint64_t id, Refusal refusal, std::string message = {}, Diagnostics diags = {});
  void note(Severity s, std::string code, std::string text);
  std::string describe(const Fault& f) const;
  std::string interlock_text(const ServoEvent& e) const;

  config::MachineProfile profile_;
  ServoConfig servo_config_;
  plan::MachineLimits limits_;
  plan::PlannerConfig planner_config_;
  ServoChannels* channels_;
  std::shared_ptr<ProgramSource> source_;

  mutable std::mutex inbox_mutex_;
  std::vector<std::pair<std::uint64_t, Request>> inbox_;
  /// Set with every submit(): service() takes the lock only when there is something to take.
  std::atomic<bool> inbox_filled_{false};
  std::vector<std::pair<std::uint64_t, Request>> requests_;  ///< controller thread: being handled
  std::uint64_t next_id_ = 1;

  mutable std::mutex out_mutex_;  ///< outcomes, notes, the published status
  std::map<std::uint64_t, Outcome> outcomes_;
  std::vector<Note> notes_;
  ControllerStatus published_;

  // Controller thread only.
  /// The servo's status as last read (the triple buffer's reader slot).
  const ServoStatus& servo() const noexcept { return channels_->status.front(); }
  std::uint64_t described_fault_tick_ = ~std::uint64_t{0};
  std::shared_ptr<const canon::Program> program_;  ///< the open program
  /// The planner started when the program was opened, for its first run (a program is checked
  /// once, not at open and again at cycle start).
  std::unique_ptr<plan::Planner> prepared_;
  std::shared_ptr<const canon::Program> prepared_program_;
  std::string program_name_;
  std::string program_path_;  ///< "" when given as a canon::Program
  bool program_block_delete_ = false;
  bool block_delete_ = false;
  std::unique_ptr<Run> run_;  ///< the run started last, until the servo reports its end
  std::uint32_t run_counter_ = 0;
  std::uint64_t runs_finished_ = 0;
};

}  // namespace opencnc::control
