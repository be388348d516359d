// SPDX-License-Identifier: GPL-3.0-or-later
// Job — one execution of a program (the main one, an MDI line, an auxiliary program): its stream
// read ahead of the machine, every move checked before the planner sees it, the sync points
// answered from what the servo reports, and the servo runs ("legs") it takes. Controller thread.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "offset_track.hpp"
#include "opencnc/control/channels.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/controller/controller_status.hpp"
#include "opencnc/controller/events.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/plan/planner.hpp"

namespace opencnc::controller::detail {

/// What a job uses of the controller.
struct JobHost {
  control::ServoChannels* channels = nullptr;
  const control::ServoConfig* servo = nullptr;
  const plan::MachineLimits* limits = nullptr;
  const plan::PlannerConfig* planner = nullptr;
  MoveCheck* check = nullptr;
  std::size_t readahead_moves = 2000;
  double readahead_s = 5;
  /// The preflight checked this very program from this very start with these very tools: its
  /// moves up to the first sync point are the ones it checked (interpretation is deterministic),
  /// so they are not checked twice. After a sync point the real answers may differ from the
  /// assumed ones: every move is checked again.
  bool prechecked = false;
  /// The job's first run continues an interrupted program's process (StartRun's `flag`): a resume
  /// at a segment, or a feature's auxiliary moves between the interruption and that resume.
  bool continues = false;
  std::function<std::uint64_t()> next_command_id;
  std::function<void(ControllerEvent)> log;
  /// Sends a servo command; false when the queue is full.
  std::function<bool(const control::Command&)> send;
  /// The send order of the request that started the job: its first StartRun carries it, so that a
  /// stop sent after the request drops the start (Command::seq); later legs take a new number.
  std::uint64_t request_seq = 0;
  /// Servo run ids are the controller's to hand out.
  std::function<std::uint32_t()> next_run_id;
  /// Whether the features let the interpreter read on past a sync point the machine has passed
  /// (Feature::allow_continue); null: always.
  std::function<bool(const SyncCheck&)> may_continue;
};

class Job {
 public:
  Job(JobKind kind, std::uint32_t id, std::string name, control::Mode mode,
      std::unique_ptr<ProgramStream> stream, JobHost host);
  ~Job();

  /// Reads the first moves, checks them, plans, queues the first blocks and sends StartRun with
  /// the id `command_id` (the servo's answer to it is the answer to the request that started the
  /// job). False, with the reasons in `diags`, when the program fails before any motion.
  bool start(std::uint64_t command_id, Diagnostics& diags);
  /// One servo event (in order) with the status read in the same service.
  void on_servo_event(const control::ServoEvent& e, const control::ServoStatus& s);
  /// The periodic work: read ahead, answer sync points, feed the planner, free what is passed.
  void service(const control::ServoStatus& s);

  bool ended() const noexcept { return ended_; }
  /// The machine has answered the sync point, but a feature holds the interpreter there.
  bool held_at_sync() const noexcept { return held_.has_value(); }
  JobEnd end_reason() const noexcept { return end_; }
  /// The error that ended the job (JobEnd::Error), with file and line.
  const Diagnostics& errors() const noexcept { return errors_; }

  JobKind kind() const noexcept { return kind_; }
  std::uint32_t id() const noexcept { return id_; }
  const std::string& name() const noexcept { return name_; }
  control::Mode mode() const noexcept { return mode_; }
  std::uint32_t run_id() const noexcept { return leg_.run_id; }
  /// Job move number of the servo's move `segment` of the current run.
  std::uint64_t job_segment(std::uint64_t segment) const noexcept { return leg_.first_move + segment; }
  /// The run's program window (its moves from the leg's first on; the ones before the run's
  /// position may be released).
  const canon::Program& program() const noexcept { return stream_->program(); }
  std::uint64_t moves_read() const noexcept { return leg_.first_move + stream_->program().size(); }
  SyncKind sync_wait() const noexcept { return waiting_ ? stream_->sync_request().kind : SyncKind::None; }
  const SourceLocation& sync_location() const noexcept { return stream_->sync_request().where; }
  SourceLocation interpreter_location() const { return stream_->location(); }
  /// The source of the servo's (context, line) in the current run.
  SourceLocation locate_servo(std::uint32_t context, std::uint32_t line) const;
  /// The text of a program message the servo passed (action `action` of run `run_id`).
  std::optional<std::string> message(std::uint32_t run_id, std::uint32_t action) const;
  /// The program window and first job move of a servo run (null if it is no longer held).
  TraceContext trace_context(std::uint32_t run_id) const;
  /// The offsets in effect before the job's stream sets any (the MDI session's, carried over).
  void set_initial_offsets(const WorkOffsets& o) { offsets_ = OffsetTrack(o); }
  /// The offsets of the servo's move `segment` of the current run (segments asked for must
  /// not go backward), and after everything read so far.
  const WorkOffsets& offsets_at(std::uint64_t segment) {
    return offsets_.at(static_cast<std::size_t>(segment));
  }
  const WorkOffsets& latest_offsets() const noexcept { return offsets_.latest(); }
  /// The end of the servo's move `segment` of the current run, if the window still holds it.
  std::optional<Pose> move_end(std::uint64_t segment) const;

 private:
  struct Leg {
    std::uint32_t run_id = 0;
    std::uint64_t command_id = 0;
    std::uint64_t first_move = 0;  ///< job move number of the leg's move 0
    std::unique_ptr<plan::Planner> planner;
    std::size_t checked = 0;        ///< moves of the leg checked and handed to the planner
    std::uint32_t next_action = 0;  ///< next action to consider for a MachineAction record
    bool pumped_once = false;
    bool ended = false;
    /// Cumulative nominal time (s) up to the end of each held move, for the read-ahead in seconds.
    std::deque<double> time_to;
    std::size_t time_first = 0;  ///< leg move of time_to.front()
    std::uint64_t tripped_segment = 0;
    bool tripped = false;
  };

  bool begin_leg(std::uint64_t command_id, Diagnostics& diags);
  void read_ahead(const control::ServoStatus& s);
  bool wants_more(const control::ServoStatus& s) const;
  void check_new_moves();
  void enter_sync();
  void answer(const SyncAnswer& a);
  void answer_when_allowed();
  void push_actions();
  void pump();
  void release(const control::ServoStatus& s);
  void fail(const Diagnostics& why);
  void finish(JobEnd end);
  double nominal_time(canon::SegmentId move) const;
  std::uint32_t sync_action() const;

  JobKind kind_;
  std::uint32_t id_;
  std::string name_;
  control::Mode mode_;
  std::unique_ptr<ProgramStream> stream_;
  JobHost host_;
  Leg leg_;
  OffsetTrack offsets_;
  std::uint32_t previous_run_id_ = 0;  ///< the leg before (its samples may still come)
  bool waiting_ = false;               ///< the stream waits at a sync point for the servo
  std::uint32_t waiting_action_ = 0;   ///< the action of that sync point in the leg
  int waiting_tool_ = 0;               ///< the tool of a tool-change sync point
  std::optional<SyncAnswer> held_;     ///< the machine's answer, held while a feature says wait
  double input_value_ = 0;             ///< the last M66 result of the run
  bool failing_ = false;               ///< an error: stop at the end of the good moves, then abort
  bool prechecked_ = false;            ///< JobHost::prechecked, until the first sync point
  std::size_t released_to_ = 0;        ///< the move release() last freed up to
  bool abort_sent_ = false;
  bool ended_ = false;
  JobEnd end_ = JobEnd::Finished;
  Diagnostics errors_;
};

}  // namespace opencnc::controller::detail
