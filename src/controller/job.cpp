// SPDX-License-Identifier: GPL-3.0-or-later
// One program execution: read ahead, check, plan, wait at sync points, answer them, leg by leg.
#include "job.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "opencnc/canon/program_tail.hpp"
#include "opencnc/control/machine_action.hpp"
#include "opencnc/controller/preflight.hpp"

namespace opencnc::controller::detail {

namespace {

/// Moves asked of the stream per read.
constexpr std::size_t kReadBatch = 512;
/// Actions looked at (backwards from the newest) for the one a sync point stands for.
constexpr std::size_t kSyncActionScan = 64;

SyncAnswer at_rest(SyncKind kind, const control::ServoStatus& s) {
  SyncAnswer a;
  a.kind = kind;
  a.position = s.commanded;
  a.probe_position = s.commanded;
  return a;
}

}  // namespace

Job::Job(JobKind kind, std::uint32_t id, std::string name, control::Mode mode,
         std::unique_ptr<ProgramStream> stream, JobHost host)
    : kind_(kind),
      id_(id),
      name_(std::move(name)),
      mode_(mode),
      stream_(std::move(stream)),
      host_(std::move(host)),
      prechecked_(host_.prechecked) {}

Job::~Job() = default;

bool Job::start(std::uint64_t command_id, Diagnostics& diags) {
  if (stream_->state() == StreamState::Error) {
    for (const Diagnostic& d : stream_->diagnostics().items()) diags.add(d);
    return false;
  }
  return begin_leg(command_id, diags);
}

// A servo run over the stream's current window. The first moves are read and checked before the
// run starts: a program (an MDI line) whose first moves fail starts nothing.
bool Job::begin_leg(std::uint64_t command_id, Diagnostics& diags) {
  const bool first_leg = leg_.run_id == 0;
  const std::uint64_t first_move = leg_.first_move;
  previous_run_id_ = leg_.run_id;
  leg_ = Leg{};
  leg_.first_move = first_move;
  leg_.run_id = host_.next_run_id();
  leg_.command_id = command_id;
  leg_.planner = std::make_unique<plan::Planner>(*host_.limits, *host_.planner);
  if (!leg_.planner->start_stream(stream_->program())) {
    for (const Diagnostic& d : leg_.planner->diagnostics().items()) diags.add(d);
    return false;
  }
  leg_.time_to.push_back(0.0);  // the time to the end of "move −1": the start
  leg_.time_first = 0;
  released_to_ = 0;
  waiting_ = false;
  const control::ServoStatus& s = host_.channels->status.front();
  read_ahead(s);
  if (failing_) {  // nothing has moved: the request is refused with the reasons
    for (const Diagnostic& d : errors_.items()) diags.add(d);
    return false;
  }
  control::Command c;
  c.kind = control::CommandKind::StartRun;
  c.id = command_id;
  c.seq = first_leg ? host_.request_seq : 0;
  c.run_id = leg_.run_id;
  c.run_mode = mode_;
  c.flag = first_leg && host_.continues;
  c.first_block = host_.channels->blocks.pushed();
  c.first_action = host_.channels->actions.pushed();
  push_actions();
  pump();  // blocks first, so that the servo finds them when it starts
  if (!host_.send(c)) {
    diags.error("", 0, 0, "the servo's command queue is full", "control.busy");
    return false;
  }
  return true;
}

// --- reading ahead ---------------------------------------------------------------------------

void Job::read_ahead(const control::ServoStatus& s) {
  while (!failing_ && !waiting_ && stream_->state() == StreamState::Reading && wants_more(s)) {
    const std::size_t before = stream_->program().size();
    stream_->read(kReadBatch);
    check_new_moves();
    if (stream_->program().size() == before) break;  // a long computation: on at the next service
  }
  if (failing_) return;
  switch (stream_->state()) {
    case StreamState::Reading:
      break;
    case StreamState::Sync:
      check_new_moves();
      if (!waiting_ && !failing_) enter_sync();
      break;
    case StreamState::Finished:
      check_new_moves();
      if (!failing_) leg_.planner->stream_end();
      break;
    case StreamState::Error:
      check_new_moves();
      fail(stream_->diagnostics());
      break;
  }
}

// The planner's look-ahead always gets what it asks for; beyond that the interpreter stays within
// the profile's read-ahead, in moves and in seconds of programmed motion.
bool Job::wants_more(const control::ServoStatus& s) const {
  if (leg_.planner->wants_input()) return true;
  const std::size_t at = s.run_id == leg_.run_id ? static_cast<std::size_t>(s.segment) : 0;
  const std::size_t ahead = leg_.checked > at ? leg_.checked - at : 0;
  if (ahead >= host_.readahead_moves) return false;
  const std::size_t index = at >= leg_.time_first ? at - leg_.time_first : 0;
  const double now = index < leg_.time_to.size() ? leg_.time_to[index] : leg_.time_to.back();
  return leg_.time_to.back() - now < host_.readahead_s;
}

// Every move is checked before the planner may read it: against the soft limits and the planner's
// own checks, now with the real answers of the sync points passed. A move that fails never runs:
// the motion stops at the end of the one before.
void Job::check_new_moves() {
  const canon::Program& p = stream_->program();
  Diagnostics d;
  while (!failing_ && leg_.checked < p.size()) {
    if (!prechecked_ && !host_.check->check(p, leg_.checked, d)) {
      fail(d);
      break;
    }
    leg_.time_to.push_back(leg_.time_to.back() + nominal_time(leg_.checked));
    ++leg_.checked;
  }
  leg_.planner->stream_readable(leg_.checked);
}

double Job::nominal_time(canon::SegmentId move) const {
  const canon::Program& p = stream_->program();
  const double length = move_length(p, move);
  const canon::Move& m = p.move(move);
  if (m.kind == canon::MoveKind::Traverse) {
    double v = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kAxisCount; ++i) {
      if (host_.limits->axes.has(static_cast<Axis>(i))) v = std::min(v, (*host_.limits)[i].max_velocity);
    }
    return std::isfinite(v) && v > 0 ? length / v : 0.0;
  }
  const double f = p.feed(move);
  if (!(f > 0)) return 0.0;
  if (m.flags & canon::kInverseTime) return 60.0 / f;
  return length / (f / 60.0);  // per revolution: as if one revolution a second, a rough guess
}

// --- sync points -----------------------------------------------------------------------------

// The action of the leg that stands for the sync point the stream waits at (kNoAction for a
// probe move's end, and for an M61, which needs no machine answer).
std::uint32_t Job::sync_action() const {
  const canon::Program& p = stream_->program();
  const SyncKind k = stream_->sync_request().kind;
  if (k == SyncKind::Probe) return traj::kNoAction;
  const std::size_t first = std::max(p.first_held_action(), p.action_count() > kSyncActionScan
                                                                 ? p.action_count() - kSyncActionScan
                                                                 : std::size_t{0});
  for (std::size_t a = p.action_count(); a-- > first;) {
    const canon::ActionKind ak = p.action(a).kind;
    const bool match = (k == SyncKind::Input && ak == canon::ActionKind::WaitInput) ||
                       (k == SyncKind::ToolChange && ak == canon::ActionKind::ChangeTool) ||
                       (k == SyncKind::ProgramStop &&
                        (ak == canon::ActionKind::ProgramStop || ak == canon::ActionKind::OptionalStop));
    if (match) return static_cast<std::uint32_t>(a);
  }
  return traj::kNoAction;
}

void Job::enter_sync() {
  const SyncRequest& r = stream_->sync_request();
  prechecked_ = false;  // what follows may rest on the machine's answer
  const std::uint32_t action = sync_action();
  if (r.kind != SyncKind::Probe && action == traj::kNoAction) {
    // M61 names the tool in the spindle: nothing for the machine to do, nothing to wait for.
    const canon::Program& p = stream_->program();
    SyncAnswer a;
    a.kind = r.kind;
    a.position = p.empty() ? p.start() : p.end(p.size() - 1);
    a.probe_position = a.position;
    stream_->answer(a);
    return;
  }
  waiting_ = true;
  waiting_action_ = action;
  waiting_tool_ = r.kind == SyncKind::ToolChange && action != traj::kNoAction
                      ? stream_->program().action(action).index
                      : 0;
  ControllerEvent e;
  e.kind = ControllerEventKind::SyncWait;
  e.job = kind_;
  e.job_id = id_;
  e.sync = r.kind;
  e.location = r.where;
  e.text = fmt::format("waits for the {} at {}", to_string(r.kind), to_string(r.where));
  host_.log(std::move(e));
  // The motion stops at the sync point; what follows is planned once the machine has answered.
  leg_.planner->stream_flush();
}

void Job::answer(const SyncAnswer& a) {
  const SyncRequest request = stream_->sync_request();
  waiting_ = false;
  stream_->answer(a);
  ControllerEvent e;
  e.kind = ControllerEventKind::SyncDone;
  e.job = kind_;
  e.job_id = id_;
  e.sync = request.kind;
  e.location = request.where;
  switch (request.kind) {
    case SyncKind::Probe:
      e.text = a.probe_tripped ? fmt::format("the probe tripped at X{:.4f} Y{:.4f} Z{:.4f}", a.probe_position[0],
                                             a.probe_position[1], a.probe_position[2])
                               : "the probe move ended without a trip";
      break;
    case SyncKind::Input:
      e.text = fmt::format("the input read {}", a.input_value);
      break;
    default:
      e.text = fmt::format("the {} is done", to_string(request.kind));
      break;
  }
  host_.log(std::move(e));
}

// --- servo events ------------------------------------------------------------------------------

void Job::on_servo_event(const control::ServoEvent& e, const control::ServoStatus& s) {
  if (ended_) return;
  switch (e.kind) {
    case control::EventKind::Refused:
      if (e.command == control::CommandKind::StartRun && e.command_id == leg_.command_id)
        finish(e.refusal == control::Refusal::Superseded ? JobEnd::Aborted : JobEnd::Fault);
      return;
    case control::EventKind::InputRead:
      if (e.run_id == leg_.run_id) input_value_ = e.value;
      return;
    case control::EventKind::ProbeTripped:
      if (e.run_id == leg_.run_id) {
        leg_.tripped = true;
        leg_.tripped_segment = e.segment;
      }
      return;
    case control::EventKind::SyncPassed:
      if (e.run_id != leg_.run_id || !waiting_ || e.action != waiting_action_) return;
      {
        SyncAnswer a = at_rest(stream_->sync_request().kind, s);
        a.input_value = input_value_;
        held_ = a;
        answer_when_allowed();
      }
      return;
    case control::EventKind::RunEnded:
      if (e.run_id != leg_.run_id) return;
      leg_.ended = true;
      switch (e.run_end) {
        case control::RunEnd::Finished:
          finish(failing_ ? JobEnd::Error : JobEnd::Finished);
          return;
        case control::RunEnd::ProbeTripped: {
          // The machine stopped inside the probe move: the interpreter learns where, and what
          // follows runs from there in a new leg.
          std::size_t from = stream_->program().size();
          if (waiting_ && stream_->sync_request().kind == SyncKind::Probe) {
            SyncAnswer a = at_rest(SyncKind::Probe, s);
            a.probe_tripped = true;
            a.probe_position = s.probe_position;
            answer(a);
          } else {
            from = std::min<std::size_t>(leg_.tripped_segment + 1, stream_->program().size());
          }
          if (from >= stream_->program().size() && stream_->state() == StreamState::Finished) {
            finish(JobEnd::Finished);  // the probe move was the program's last
            return;
          }
          const std::uint64_t next_first = leg_.first_move + from;
          offsets_.scan(stream_->program());
          offsets_.restart(from);
          stream_->restart_at(s.commanded, from);
          leg_.first_move = next_first;
          Diagnostics d;
          if (!begin_leg(host_.next_command_id(), d)) {
            if (!failing_) fail(d);
            finish(JobEnd::Error);
          }
          return;
        }
        case control::RunEnd::Aborted:
          finish(failing_ ? JobEnd::Error : JobEnd::Aborted);
          return;
        case control::RunEnd::Faulted:
        case control::RunEnd::EStopped:
        case control::RunEnd::MachineOff:
          finish(JobEnd::Fault);
          return;
      }
      return;
    default:
      return;
  }
}

// --- the periodic work -------------------------------------------------------------------------

// The machine has passed the sync point; the interpreter reads on once every feature agrees
// (Feature::allow_continue), else the job stands there and asks again next service().
void Job::answer_when_allowed() {
  if (!held_) return;
  if (host_.may_continue) {
    const SyncRequest& r = stream_->sync_request();
    SyncCheck c;
    c.job = kind_;
    c.kind = r.kind;
    c.where = r.where;
    c.tool_index = waiting_tool_;
    if (!host_.may_continue(c)) return;
  }
  const SyncAnswer a = *held_;
  held_.reset();
  answer(a);
}

void Job::service(const control::ServoStatus& s) {
  if (ended_) return;
  answer_when_allowed();
  if (!failing_) read_ahead(s);
  push_actions();
  pump();
  if (failing_ && !abort_sent_ && s.run_id == leg_.run_id && s.motion == traj::RunState::Starved &&
      s.path_velocity == 0 && host_.channels->blocks.available() == 0) {
    // Stopped at the end of the last good move: the run ends there.
    control::Command c;
    c.kind = control::CommandKind::Abort;
    c.id = host_.next_command_id();
    abort_sent_ = host_.send(c);
  }
  release(s);
}

void Job::push_actions() {
  const canon::Program& p = stream_->program();
  offsets_.scan(p);  // every action read, before release() may free it
  while (leg_.next_action < p.action_count() && p.action(leg_.next_action).before_move <= leg_.checked) {
    const auto a = machine_action(p, leg_.next_action, host_.servo);
    if (a && !host_.channels->actions.try_push(*a)) break;
    ++leg_.next_action;
  }
}

// The planner refills the queue in batches, once a quarter of it is free (thousands of blocks,
// seconds of motion, are still queued then): planning many blocks in a row keeps its code and
// data in the cache, where a block or two every period did not.
void Job::pump() {
  if (leg_.ended) return;
  constexpr std::size_t kRefillSlots = traj::BlockQueue::kCapacity / 4;
  if (leg_.pumped_once && host_.channels->blocks.free_slots() < kRefillSlots) return;
  leg_.pumped_once = true;
  if (leg_.planner->pump(host_.channels->blocks) == plan::PlanStatus::Failed) fail(leg_.planner->diagnostics());
}

// What every reader has passed is freed: the planner's reader, the servo (and the trace samples on
// its moves, which every observer has seen by now), the actions whose records are queued.
void Job::release(const control::ServoStatus& s) {
  const canon::Program& p = stream_->program();
  std::size_t move = std::min(leg_.checked, leg_.planner->oldest_move_needed());
  if (s.run_id == leg_.run_id) move = std::min(move, static_cast<std::size_t>(s.segment_first));
  else move = 0;  // the run has not started yet
  // Whole chunks are freed: looking every few hundred moves is enough.
  if (move < released_to_ + 256) return;
  released_to_ = move;
  std::size_t action = std::min<std::size_t>(leg_.next_action, leg_.planner->oldest_action_needed());
  // Messages are looked up when the servo passes them: keep the actions of the moves kept.
  std::size_t lo = p.first_held_action(), hi = action;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (p.action(mid).before_move + 1 < move) lo = mid + 1;
    else hi = mid;
  }
  stream_->release(move, lo);
  while (leg_.time_first + 1 < move && leg_.time_to.size() > 1) {
    leg_.time_to.pop_front();
    ++leg_.time_first;
  }
}

// --- ends --------------------------------------------------------------------------------------

void Job::fail(const Diagnostics& why) {
  for (const Diagnostic& d : why.items()) errors_.add(d);
  if (failing_) return;
  failing_ = true;
  waiting_ = false;
  // The motion stops at the end of what was checked: nothing after the failure is ever read.
  if (leg_.planner) leg_.planner->stream_flush();
}

void Job::finish(JobEnd end) {
  if (ended_) return;
  ended_ = true;
  end_ = end;
}

// --- what the controller shows -------------------------------------------------------------

SourceLocation Job::locate_servo(std::uint32_t context, std::uint32_t line) const {
  return locate(stream_->program().sources(), context, line);
}

std::optional<std::string> Job::message(std::uint32_t run_id, std::uint32_t action) const {
  const canon::Program& p = stream_->program();
  if (run_id != leg_.run_id || action < p.first_held_action() || action >= p.action_count()) return std::nullopt;
  return p.text(p.action(action).text);
}

std::optional<Pose> Job::move_end(std::uint64_t segment) const {
  const canon::Program& p = stream_->program();
  if (segment < p.first_held_move() || segment >= p.size()) return std::nullopt;
  return p.end(static_cast<canon::SegmentId>(segment));
}

TraceContext Job::trace_context(std::uint32_t run_id) const {
  TraceContext c;
  c.job = kind_;
  c.job_id = id_;
  if (run_id != leg_.run_id) return c;
  c.program = &stream_->program();
  c.first_move = leg_.first_move;
  return c;
}

}  // namespace opencnc::controller::detail
