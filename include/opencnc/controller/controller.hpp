// SPDX-License-Identifier: GPL-3.0-or-later
// controller::Controller — the non-real-time half of the controller and the one API of every front
// end: requests in (thread-safe), status, answers and a numbered event log out. It is a hub:
// observers follow its events, status and trace; features answer requests of their own; jobs (the
// main program, MDI lines, auxiliary programs) stream through the interpreter in execute mode
// and stop at sync points until the machine has answered.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/control/channels.hpp"
#include "opencnc/control/command.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/controller/controller_status.hpp"
#include "opencnc/controller/events.hpp"
#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/controller/request.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/plan/planner.hpp"

namespace opencnc::controller {

namespace detail {
class Job;
class TaskRunner;
}  // namespace detail
class MachineMoveCheck;

/// How a controller runs.
struct ControllerOptions {
  /// Long work (a preflight, the replay before a resume) on a thread of its own while service()
  /// goes on reading the servo and publishing the status; later requests (but the urgent lane's)
  /// wait their turn behind it. Off (virtual time): it runs inside service(), so a run repeats bit
  /// for bit; the tick then waits for it as well.
  bool long_work_on_thread = false;
};

/// The open (main) program: what the preflight found, and what it was checked for.
struct OpenProgram {
  std::string name;
  std::string path;                                     ///< "" when given as a canon::Program
  std::shared_ptr<const canon::Program> program;        ///< when given as a canon::Program
  Preflight preflight;
};

/// The non-real-time half of the controller. `submit()`, `outcome()`, `status()`, `events()`,
/// `attach()`, `detach()`, `add_feature()` and `open_program()` may be called from any thread;
/// `service()` from one thread only (the controller's, or the driver of virtual time between
/// ticks). Nothing here is real-time.
class Controller final : private FeatureHost {
 public:
  /// `channels` must outlive the controller; `source` turns G-code into programs (may be null:
  /// then only programs given as canon::Program can run).
  Controller(const config::MachineProfile& profile, control::ServoChannels& channels,
             std::shared_ptr<ProgramSource> source = nullptr, ControllerOptions options = {});
  ~Controller() override;
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  /// Queues a request; returns its id (the answer comes as its Outcome). A request of the urgent
  /// lane (takes_urgent_lane) is in the servo's queue when this returns: the next tick acts on it,
  /// whatever service() is doing. Any thread.
  std::uint64_t submit(Request r) override;
  /// The answer to request `id`, once known. Any thread.
  std::optional<Outcome> outcome(std::uint64_t id) const;
  /// The newest status. Any thread.
  ControllerStatus status() const;
  /// The numbered event log: follow it with an EventCursor of your own. Any thread.
  const EventLog& events() const noexcept { return log_; }
  /// Attaches an observer (from the next service() on; it sees the log from then). Returns an
  /// id for detach(). Any thread.
  std::uint64_t attach(std::shared_ptr<ControllerObserver> observer, ObserverOptions options = {});
  /// Detaches an observer (from the next service() on). Any thread.
  void detach(std::uint64_t id);
  /// Adds a feature: an observer that answers requests::Feature requests for its name(). False
  /// when the name is taken. Any thread.
  bool add_feature(std::shared_ptr<Feature> feature, ObserverOptions options = {});
  /// The open program (its preflight summary and warnings), if any. Any thread.
  std::optional<OpenProgram> open_program() const;
  /// Adds what a feature's process adds around a move to the soft-limit check of every move (the
  /// preflight's and the running program's), from the next service() on. Any thread; before the
  /// controller checks a program (a set-up's install()).
  void add_move_reach(MoveReachFactory reach);
  /// Adds the words of a feature's events, faults and waits (extensions.hpp), from the next
  /// service() on. Any thread.
  void add_texts(std::shared_ptr<const EventTexts> texts);

  /// The periodic work: reads the servo's events, status and trace, handles queued requests,
  /// keeps the interpreter and the planner ahead of the servo, tells the observers. Controller
  /// thread. Deterministic for the same inputs.
  void service();

  /// The servo configuration and the profile in force. Controller thread (they change with an
  /// EditProfile request).
  const control::ServoConfig& servo_config() const noexcept { return servo_config_; }
  const config::MachineProfile& profile() const noexcept override { return profile_; }
  /// A copy of the profile in force (after the last EditProfile). Any thread.
  config::MachineProfile current_profile() const;

 private:
  struct Attached {
    std::uint64_t id = 0;
    std::shared_ptr<ControllerObserver> observer;
    ObserverOptions options;
    std::uint64_t cursor = 0;      ///< last log entry delivered
    std::uint64_t next_status = 0;  ///< tick of the next on_status
  };

  // FeatureHost
  const ControllerStatus& current_status() const override { return published_; }
  void note(Severity s, std::string code, std::string text) override;
  std::uint64_t defer() override;
  void answer(std::uint64_t id, Outcome outcome) override;
  void answer_after(std::function<void()> work, std::function<Outcome()> then) override;
  void poll_features();

  void read_servo();
  void deliver_trace();
  void on_event(const control::ServoEvent& e);
  void handle(std::uint64_t id, Request& r);
  void handle_servo(std::uint64_t id, const Request& r);
  void open_file(std::uint64_t id, const std::string& path);
  void open_canon(std::uint64_t id, std::shared_ptr<const canon::Program> program, std::string name);
  void mdi(std::uint64_t id, const std::string& line);
  void cycle_start(std::uint64_t id, const Request& r);
  void run_auxiliary(std::uint64_t id, const requests::RunAuxiliary& r);
  void resume_program(std::uint64_t id, const requests::ResumeProgram& r);
  void feature(std::uint64_t id, const requests::Feature& r);
  // Profile edits (profile_change.cpp).
  void edit_profile(std::uint64_t id, const requests::EditProfile& r);
  bool settle_profile_change(const control::ServoEvent& e);
  struct ProfileChange;
  bool open_program_passes(const config::MachineProfile& next, Diagnostics& needs);
  /// The move check of the servo configuration in force, with the features' reaches.
  std::unique_ptr<MachineMoveCheck> make_move_check() const;
  void swap_profile(config::MachineProfile profile);
  bool features_allow_start(std::uint64_t id, const StartCheck& start);
  bool features_allow_continue(const SyncCheck& sync);
  /// Refuses when a job cannot start now (mode `mode`, idle, homed, no job running).
  bool ready_for_job(std::uint64_t id, control::Mode mode, const char* what);
  Preflight preflight_file(const std::string& path, const Pose& at, bool block_delete, ScanCancel cancel);
  Preflight preflight_canon(const canon::Program& program);
  /// `work` as the long task of request `id` (on the task thread, or at once), then `then` on the
  /// controller's thread; a task that throws is answered with its message.
  void run_long(std::uint64_t id, std::function<void()> work, std::function<void()> then);
  void finish_long_work();
  /// Whether the request being handled was sent before a halt (`halts_only`) or any stop that has
  /// been sent since: it is then answered control.superseded and true is returned.
  bool superseded(std::uint64_t id, bool halts_only);
  ScanCancel cancel_token() const noexcept { return {&halt_seq_, handling_seq_}; }
  void finish_open(std::uint64_t id, const std::string& path, Preflight pf, const Pose& at, bool block_delete,
                   std::string stamp, std::uint64_t version);
  void start_checked(std::uint64_t id, const std::string& path, Preflight pf, const Pose& at,
                     bool block_delete, std::string stamp, std::uint64_t version);
  /// Sends a command to the tick in the order of sending: `c.seq` as set (a request's own), or
  /// the next number. False when the queue is full. Controller thread.
  bool send(control::Command c);
  /// `resumes`: the job resumes the open program at a segment (its first run continues the
  /// process that was interrupted there, e.g. the torch keeps the interrupted cut's voltage).
  void start_job(std::uint64_t id, JobKind kind, std::string name, control::Mode mode,
                 std::unique_ptr<ProgramStream> stream, bool prechecked = false, bool resumes = false);
  void end_job();
  void forward(std::uint64_t id, const control::Command& c);
  std::uint64_t next_seq();
  void finish(std::uint64_t id, control::Refusal refusal, std::string message = {}, Diagnostics diags = {});
  void log(ControllerEvent e);
  void publish();
  void update_locations();
  void update_offsets(bool same_run);
  std::string wait_text() const;
  void tell_observers();
  void take_attachments();
  std::string describe(const control::Fault& f) const;
  std::string interlock_text(const control::ServoEvent& e) const;
  std::string seek_text(const control::ServoEvent& e) const;
  std::uint64_t new_id();

  config::MachineProfile profile_;
  control::ServoConfig servo_config_;
  plan::MachineLimits limits_;
  plan::PlannerConfig planner_config_;
  control::ServoChannels* channels_;
  std::shared_ptr<ProgramSource> source_;
  std::vector<MoveReachFactory> reaches_;  ///< controller thread: the features' (add_move_reach)
  std::vector<std::shared_ptr<const EventTexts>> texts_;  ///< controller thread: the features' (add_texts)
  std::unique_ptr<MachineMoveCheck> check_;
  EventLog log_;

  /// A request as submitted, with its place in the order of sending (Command::seq).
  struct Submitted {
    std::uint64_t id = 0;
    std::uint64_t seq = 0;
    Request request;
  };
  mutable std::mutex
      inbox_mutex_;  ///< the inbox, the id and send counters, the urgent lane, attachments waiting
  std::vector<Submitted> inbox_;
  /// Set with every submit(): service() takes the lock only when there is something to take.
  std::atomic<bool> inbox_filled_{false};
  std::deque<Submitted> backlog_;  ///< controller thread: waiting their turn (behind a long task)
  std::uint64_t next_id_ = 1;
  std::uint64_t next_seq_ = 0;  ///< under inbox_mutex_: the send order of requests and commands
  /// The send order of the latest stop / halt submitted (written under inbox_mutex_).
  std::atomic<std::uint64_t> stop_seq_{0}, halt_seq_{0};
  std::uint64_t handling_seq_ = 0;  ///< controller thread: the send order of the request being handled
  std::vector<Attached> to_attach_;
  std::vector<std::uint64_t> to_detach_;
  std::vector<std::shared_ptr<Feature>> features_to_add_;
  std::vector<MoveReachFactory> reaches_to_add_;
  std::vector<std::shared_ptr<const EventTexts>> texts_to_add_;

  mutable std::mutex out_mutex_;  ///< outcomes, the published status, the open program
  /// The answer to request `id` at `id % size()`, kept until a later id takes its place: slots built
  /// once, so answering requests for days does not grow the controller.
  struct KeptOutcome {
    std::uint64_t id = 0;
    Outcome outcome;
  };
  std::vector<KeptOutcome> outcomes_;
  ControllerStatus published_;
  std::optional<OpenProgram> open_;
  config::MachineProfile shown_profile_;  ///< profile_ for other threads (current_profile())

  // Controller thread only.
  /// The servo's status as last read (the triple buffer's reader slot).
  const control::ServoStatus& servo() const noexcept { return channels_->status.front(); }
  std::vector<Attached> observers_;
  std::map<std::string, std::shared_ptr<Feature>, std::less<>> features_;
  std::string held_by_;  ///< the feature that holds the job at a sync point ("" while none does)
  std::uint64_t handling_ = 0;  ///< the feature request being handled (0: none)
  bool deferred_ = false;       ///< its feature answers it later (FeatureHost::defer)
  std::uint64_t described_fault_tick_ = ~std::uint64_t{0};
  Pose open_at_{};               ///< where the machine stood when the open program was checked
  bool open_block_delete_ = false;
  std::string open_stamp_;       ///< the open file's size and change time when it was checked
  std::uint64_t open_version_ = 0;  ///< the source's version when it was checked
  bool block_delete_ = false;
  /// The long request under way (its task on tasks_), and what to do on this thread when it is done.
  struct LongRequest {
    std::uint64_t id = 0, seq = 0;
    std::function<void()> then;
    std::shared_ptr<std::string> failure;  ///< what the task threw
  };
  std::optional<LongRequest> long_;
  std::unique_ptr<detail::Job> job_;
  std::unique_ptr<detail::Job> retired_;  ///< the job that ended last (its last samples may come)
  std::uint32_t job_counter_ = 0;
  std::uint32_t run_counter_ = 0;
  std::uint64_t runs_finished_ = 0;
  WorkOffsets mdi_offsets_;  ///< the MDI session's interpreter's, after its last line
  /// A profile edit the tick has not answered yet: what to restore if it refuses.
  struct ProfileChange {
    std::uint64_t id = 0, stage_id = 0;
    config::MachineProfile old_profile;
    std::string old_text, message, who;
    std::vector<config::FileText> old_files;  ///< other files the change wrote (a comp file), as they were
    const char* what = "machine parameters";  ///< for the audit: "machining conditions" when only those
  };
  std::optional<ProfileChange> profile_change_;
  std::uint32_t limits_version_ = 0;       ///< counts applied profile edits
  std::uint32_t open_limits_version_ = 0;  ///< limits_version_ when the open program was checked
  // Status details that cost strings, refreshed when they change.
  std::uint32_t located_context_ = ~0u, located_line_ = ~0u, located_run_ = ~0u;
  std::uint64_t interpreter_seen_ = ~std::uint64_t{0};
  std::uint64_t location_every_ = 1;  ///< servo periods between refreshes of the interpreter's place
  struct WaitKey {
    control::State state = control::State::Off;
    control::Wait wait = control::Wait::None;
    control::StopReason stop = control::StopReason::None;
    SyncKind sync = SyncKind::None;
    std::uint32_t line = 0, context = 0;
    bool job = false;
    bool operator==(const WaitKey&) const = default;
  };
  WaitKey wait_key_{
      control::State::Off, control::Wait::None, control::StopReason::None, SyncKind::None, ~0u, ~0u, false};
  /// Last: destroyed (its thread joined) before everything its task may use.
  std::unique_ptr<detail::TaskRunner> tasks_;
};

}  // namespace opencnc::controller
