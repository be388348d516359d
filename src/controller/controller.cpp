// SPDX-License-Identifier: GPL-3.0-or-later
// Controller: requests → checks → servo commands and jobs; servo events → answers, notes and the
// event log; the observers and features told in order.
#include "opencnc/controller/controller.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <variant>

#include <fmt/format.h>

#include "alarm_text.hpp"
#include "job.hpp"
#include "opencnc/canon/move_length.hpp"
#include "opencnc/controller/preflight.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "task_runner.hpp"

namespace opencnc::controller {

namespace {

constexpr std::size_t kKeptOutcomes = 4096;
/// Status details that cost strings (where the interpreter is) refresh at most this often.
constexpr double kLocationRefreshS = 0.01;

std::string refusal_text(control::Refusal r) {
  switch (r) {
    case control::Refusal::None:
      return "";
    case control::Refusal::EStopActive:
      return "the machine is e-stopped: reset it first";
    case control::Refusal::EStopInput:
      return "the e-stop chain is still open";
    case control::Refusal::MachineOff:
      return "the machine is off: turn it on first";
    case control::Refusal::Faulted:
      return "a fault stopped the machine: reset it first";
    case control::Refusal::FaultPersists:
      return "the cause of the fault is still there";
    case control::Refusal::WrongMode:
      return "not possible in this mode";
    case control::Refusal::Busy:
      return "something is running or held";
    case control::Refusal::NotHomed:
      return "the machine must be homed first";
    case control::Refusal::NotApplicable:
      return "nothing to do in this state";
    case control::Refusal::BadValue:
      return "a value is out of range";
    case control::Refusal::LimitSwitch:
      return "a limit switch is active";
    case control::Refusal::NoProgram:
      return "no program is open";
    case control::Refusal::ProgramError:
      return "the program has errors";
    case control::Refusal::SoftLimit:
      return "the program would cross a soft limit";
    case control::Refusal::StartMismatch:
      return "the motion does not start where the machine is";
    case control::Refusal::Interlock:
      return "an interlock rule of the machine forbids it now";
    case control::Refusal::HandAxis:
      return "the axis is moved by hand (or is not where the program needs it)";
    case control::Refusal::FeatureCheck:
      return "a check before the start failed";
    case control::Refusal::NoLimitSwitch:
      return "the axis has no limit switch on that side to seek (the profile's limit_min/limit_max and "
             "seek_velocity)";
    case control::Refusal::Superseded:
      return "a stop (e-stop, machine off, abort or feed hold) sent after it acted first: it was dropped; "
             "send it again if it is still meant";
  }
  return "refused";
}

/// What the operator can do about a refusal of `command`, where the generic text would leave them
/// guessing ("nothing to do in this state"); "" when the generic text says it.
std::string what_next(control::CommandKind command, control::Refusal r) {
  switch (r) {
    case control::Refusal::NotApplicable:
      switch (command) {
        case control::CommandKind::MachineOn:
          return "the machine is already on";
        case control::CommandKind::MachineOff:
          return "the machine is already off";
        case control::CommandKind::FeedHold:
          return "nothing is running to hold";
        case control::CommandKind::Resume:
          return "nothing is held: resume continues after a feed hold";
        case control::CommandKind::CycleStart:
          return "nothing is held or stopped to continue, and no program is open to start: open one (Auto), "
                 "then cycle start";
        case control::CommandKind::Reset:
          return "nothing to reset: the machine is neither e-stopped nor faulted";
        case control::CommandKind::Abort:
          return "nothing is running to abort";
        case control::CommandKind::ToolChanged:
          return "no manual tool change is waiting";
        case control::CommandKind::StartCut:
          return "no preheat is under way: start cut ends a preheat (by time or waiting for the operator)";
        default:
          return "";
      }
    case control::Refusal::WrongMode:
      switch (command) {
        case control::CommandKind::JogContinuous:
        case control::CommandKind::JogIncrement:
        case control::CommandKind::Home:
        case control::CommandKind::SeekLimit:
        case control::CommandKind::SpindleOn:
        case control::CommandKind::Coolant:
          return "that is done in Manual mode: switch to MANUAL first";
        default:
          return "";
      }
    case control::Refusal::Busy:
      return command == control::CommandKind::SetMode
                 ? "the mode changes while nothing runs: wait for the end, or abort"
                 : "";
    default:
      return "";
  }
}

/// The refusal the servo would give for a run in `state`.
control::Refusal not_idle(control::State s) {
  switch (s) {
    case control::State::EStopped:
      return control::Refusal::EStopActive;
    case control::State::Off:
      return control::Refusal::MachineOff;
    case control::State::Faulted:
      return control::Refusal::Faulted;
    default:
      return control::Refusal::Busy;
  }
}

bool has_code(const Diagnostics& d, const char* code) {
  for (const Diagnostic& x : d.items()) {
    if (x.code == code && x.severity == Severity::Error) return true;
  }
  return false;
}

control::Refusal program_refusal(const Diagnostics& d) {
  return has_code(d, "control.soft-limit") ? control::Refusal::SoftLimit : control::Refusal::ProgramError;
}

/// A file's size and change time: a program that changed on disk since its preflight is checked again.
std::string file_stamp(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return {};
  const auto time = std::filesystem::last_write_time(path, ec);
  if (ec) return {};
  return fmt::format("{}:{}", size, time.time_since_epoch().count());
}

}  // namespace

Controller::Controller(const config::MachineProfile& profile, control::ServoChannels& channels,
                       std::shared_ptr<ProgramSource> source, ControllerOptions options)
    : profile_(profile),
      servo_config_(controller::servo_config(profile)),
      limits_(machine_limits(profile)),
      planner_config_(controller::planner_config(profile)),
      channels_(&channels),
      source_(std::move(source)),
      check_(make_move_check()),
      shown_profile_(profile),
      location_every_(static_cast<std::uint64_t>(kLocationRefreshS / servo_config_.period_s) + 1),
      tasks_(std::make_unique<detail::TaskRunner>(options.long_work_on_thread)) {
  outcomes_.resize(kKeptOutcomes);
}

Controller::~Controller() {
  halt_seq_.store(~std::uint64_t{0});  // a task under way stops at its next batch, then its thread is joined
}

// The urgent lane: a stop is in the tick's queue before this returns, from whichever thread sends
// it, numbered in the order of sending with every other request (docs/controller.md, "Stops never
// wait"). The lock is the inbox's, never held by the controller for long; the tick takes none.
std::uint64_t Controller::submit(Request r) {
  std::lock_guard lock(inbox_mutex_);
  const std::uint64_t id = next_id_++;
  const std::uint64_t seq = ++next_seq_;
  if (is_stop(r)) stop_seq_.store(seq, std::memory_order_relaxed);
  if (is_halt(r)) halt_seq_.store(seq, std::memory_order_relaxed);
  if (takes_urgent_lane(r)) {
    std::optional<control::Command> c = to_command(r);
    if (c) {
      c->id = id;
      c->seq = seq;
      // Full (32 urgent commands within one period): they act first; this one follows in order.
      if (channels_->urgent.try_push(*c)) return id;
    }
  }
  inbox_.push_back(Submitted{id, seq, std::move(r)});
  inbox_filled_.store(true, std::memory_order_release);
  return id;
}

std::uint64_t Controller::next_seq() {
  std::lock_guard lock(inbox_mutex_);
  return ++next_seq_;
}

bool Controller::send(control::Command c) {
  if (c.seq == 0) c.seq = next_seq();
  return channels_->commands.try_push(c);
}

std::uint64_t Controller::new_id() {
  std::lock_guard lock(inbox_mutex_);
  return next_id_++;
}

std::optional<Outcome> Controller::outcome(std::uint64_t id) const {
  std::lock_guard lock(out_mutex_);
  const KeptOutcome& k = outcomes_[id % outcomes_.size()];
  if (k.id != id || id == 0) return std::nullopt;
  return k.outcome;
}

ControllerStatus Controller::status() const {
  std::lock_guard lock(out_mutex_);
  ControllerStatus s = published_;
  s.servo = channels_->status.front();  // stable until the next update(), which takes the lock
  return s;
}

std::optional<OpenProgram> Controller::open_program() const {
  std::lock_guard lock(out_mutex_);
  return open_;
}

std::uint64_t Controller::attach(std::shared_ptr<ControllerObserver> observer, ObserverOptions options) {
  std::lock_guard lock(inbox_mutex_);
  const std::uint64_t id = next_id_++;
  to_attach_.push_back(Attached{id, std::move(observer), options, 0, 0});
  inbox_filled_.store(true, std::memory_order_release);
  return id;
}

void Controller::detach(std::uint64_t id) {
  std::lock_guard lock(inbox_mutex_);
  to_detach_.push_back(id);
  inbox_filled_.store(true, std::memory_order_release);
}

void Controller::add_move_reach(MoveReachFactory reach) {
  std::lock_guard lock(inbox_mutex_);
  reaches_to_add_.push_back(std::move(reach));
}

void Controller::add_texts(std::shared_ptr<const EventTexts> texts) {
  std::lock_guard lock(inbox_mutex_);
  texts_to_add_.push_back(std::move(texts));
}

std::unique_ptr<MachineMoveCheck> Controller::make_move_check() const {
  std::vector<std::unique_ptr<MoveReach>> reaches;
  for (const MoveReachFactory& f : reaches_)
    if (std::unique_ptr<MoveReach> r = f(servo_config_)) reaches.push_back(std::move(r));
  return std::make_unique<MachineMoveCheck>(servo_config_, limits_, std::move(reaches));
}

bool Controller::add_feature(std::shared_ptr<Feature> feature, ObserverOptions options) {
  std::lock_guard lock(inbox_mutex_);
  const std::string name(feature->name());
  for (const auto& f : features_to_add_) {
    if (f->name() == name) return false;
  }
  {
    // features_ is the controller thread's; a name added earlier is in one of the two lists.
    std::lock_guard out(out_mutex_);
    if (features_.count(name) != 0) return false;
  }
  features_to_add_.push_back(feature);
  to_attach_.push_back(Attached{next_id_++, std::move(feature), options, 0, 0});
  inbox_filled_.store(true, std::memory_order_release);
  return true;
}

// --- the periodic work -----------------------------------------------------------------------

void Controller::service() {
  read_servo();
  if (inbox_filled_.load(std::memory_order_acquire)) {
    take_attachments();
    std::lock_guard lock(inbox_mutex_);
    for (Submitted& s : inbox_) backlog_.push_back(std::move(s));
    inbox_.clear();
    inbox_filled_.store(false, std::memory_order_relaxed);
  }
  finish_long_work();
  // In the order of sending; a long request's work (on the task thread) holds back the rest.
  while (!long_ && !backlog_.empty()) {
    Submitted s = std::move(backlog_.front());
    backlog_.pop_front();
    handling_seq_ = s.seq;
    handle(s.id, s.request);
    handling_seq_ = 0;
    finish_long_work();  // done at once when long work runs on this thread
  }
  poll_features();
  if (job_) {
    job_->service(servo());
    if (job_->ended()) end_job();
  }
  publish();
  tell_observers();
}

void Controller::take_attachments() {
  std::vector<Attached> attach;
  std::vector<std::uint64_t> detach;
  std::vector<std::shared_ptr<Feature>> features;
  std::vector<MoveReachFactory> reaches;
  std::vector<std::shared_ptr<const EventTexts>> texts;
  {
    std::lock_guard lock(inbox_mutex_);
    attach.swap(to_attach_);
    detach.swap(to_detach_);
    features.swap(features_to_add_);
    reaches.swap(reaches_to_add_);
    texts.swap(texts_to_add_);
  }
  for (auto& t : texts) texts_.push_back(std::move(t));
  if (!reaches.empty()) {
    for (auto& r : reaches) reaches_.push_back(std::move(r));
    check_ = make_move_check();
  }
  for (Attached& a : attach) {
    a.cursor = log_.last();  // from now on
    a.next_status = servo().tick;
    observers_.push_back(std::move(a));
  }
  for (std::uint64_t id : detach) {
    std::erase_if(observers_, [id](const Attached& a) { return a.id == id; });
  }
  for (auto& f : features) {
    {
      std::lock_guard out(out_mutex_);
      features_.emplace(std::string(f->name()), f);
    }
    f->attached(*this);
  }
  bool trace = false;
  for (const Attached& a : observers_) trace = trace || a.options.trace;
  channels_->trace_enabled.store(trace, std::memory_order_relaxed);
}

void Controller::read_servo() {
  {
    std::lock_guard lock(out_mutex_);  // status() copies the front slot under it
    channels_->status.update();
  }
  deliver_trace();
  control::ServoEvent e;
  while (channels_->events.try_pop(e)) on_event(e);
}

// Every sample goes to the observers that trace, with the program window of its run: its moves are
// still held (they are freed only after this, in the job's service).
void Controller::deliver_trace() {
  if (!channels_->trace_enabled.load(std::memory_order_relaxed)) return;
  control::TraceSample s;
  while (channels_->trace.try_pop(s)) {
    TraceContext c;
    if (job_ && s.run_id == job_->run_id()) {
      c = job_->trace_context(s.run_id);
    } else if (retired_ && s.run_id == retired_->run_id()) {
      c = retired_->trace_context(s.run_id);
    }
    for (Attached& a : observers_) {
      if (!a.options.trace) continue;
      try {
        a.observer->on_trace(s, c);
      } catch (const std::exception& ex) {
        note(Severity::Error, "control.observer", fmt::format("an observer failed and was detached: {}", ex.what()));
        a.observer.reset();
      }
    }
    std::erase_if(observers_, [](const Attached& a) { return !a.observer; });
  }
}

void Controller::on_event(const control::ServoEvent& e) {
  ControllerEvent ce;
  ce.kind = ControllerEventKind::Servo;
  ce.servo = e;
  ce.segment = e.segment;
  log(ce);
  // A feature's stage of the tick raised it: the feature has its words.
  for (const auto& t : texts_) {
    if (e.kind == control::EventKind::Fault) break;  // faults are described below (describe)
    if (std::optional<EventNote> n = t->event_note(e, profile_, servo_config_)) {
      note(n->severity, std::move(n->code), std::move(n->text));
      break;
    }
  }
  switch (e.kind) {
    case control::EventKind::Accepted:
    case control::EventKind::Refused:
      if (!settle_profile_change(e)) finish(e.command_id, e.refusal, what_next(e.command, e.refusal));
      break;
    case control::EventKind::Fault:
      note(Severity::Error, fault_code(e.fault.kind), describe(e.fault));
      break;
    case control::EventKind::Message:
      if (job_) {
        if (const auto text = job_->message(e.run_id, e.action)) note(Severity::Note, "", *text);
      }
      break;
    case control::EventKind::ProcessAlarm:
    case control::EventKind::ProcessAlarmCleared:
      note(e.kind == control::EventKind::ProcessAlarm ? Severity::Warning : Severity::Note,
           "control.process-alarm",
           detail::alarm_text(profile_.alarms, e.action, e.value, e.axis == 0,
                              e.kind == control::EventKind::ProcessAlarmCleared));
      break;
    case control::EventKind::Interlock:
      note(Severity::Warning, "control.interlock", interlock_text(e));
      break;
    case control::EventKind::LimitSeek:
      note(e.action == 1 ? Severity::Note : Severity::Error, "control.seek-limit", seek_text(e));
      break;
    default:
      break;
  }
  if (job_) {
    job_->on_servo_event(e, servo());
    if (job_->ended()) end_job();
  }
}

// --- requests --------------------------------------------------------------------------------

void Controller::handle(std::uint64_t id, Request& r) {
  std::visit(
      [&](auto& body) {
        using T = std::decay_t<decltype(body)>;
        if constexpr (std::is_same_v<T, requests::OpenFile>) {
          open_file(id, body.path);
        } else if constexpr (std::is_same_v<T, requests::OpenCanon>) {
          open_canon(id, body.program, body.name);
        } else if constexpr (std::is_same_v<T, requests::Mdi>) {
          mdi(id, body.line);
        } else if constexpr (std::is_same_v<T, requests::RunAuxiliary>) {
          run_auxiliary(id, body);
        } else if constexpr (std::is_same_v<T, requests::Feature>) {
          feature(id, body);
        } else if constexpr (std::is_same_v<T, requests::ResumeProgram>) {
          resume_program(id, body);
        } else if constexpr (std::is_same_v<T, requests::EditProfile>) {
          edit_profile(id, body);
        } else if constexpr (std::is_same_v<T, requests::SetSwitch>) {
          if (body.which == SwitchKind::BlockDelete) {
            block_delete_ = body.on;
            finish(id, control::Refusal::None);
          } else {
            handle_servo(id, r);
          }
        } else {
          handle_servo(id, r);
        }
      },
      r.body);
}

void Controller::handle_servo(std::uint64_t id, const Request& r) {
  if (const auto* s = std::get_if<requests::Servo>(&r.body)) {
    if (s->kind == control::CommandKind::CycleStart) return cycle_start(id, r);
    if (s->kind == control::CommandKind::StartRun)
      return finish(id, control::Refusal::BadValue, "start-run is the controller's own command");
  }
  const std::optional<control::Command> c = to_command(r);
  if (!c) return finish(id, control::Refusal::BadValue, "this request has no servo command");
  forward(id, *c);
}

void Controller::forward(std::uint64_t id, const control::Command& command) {
  control::Command c = command;
  c.id = id;
  c.seq = handling_seq_;
  if (!send(c)) finish(id, control::Refusal::Busy, "the servo's command queue is full");
}

// --- long work -------------------------------------------------------------------------------

void Controller::run_long(std::uint64_t id, std::function<void()> work, std::function<void()> then) {
  auto failure = std::make_shared<std::string>();
  long_ = LongRequest{id, handling_seq_, std::move(then), failure};
  tasks_->start([work = std::move(work), failure] {
    try {
      work();
    } catch (const std::exception& ex) {
      *failure = ex.what();
    } catch (...) {
      *failure = "an unknown error";
    }
  });
}

void Controller::finish_long_work() {
  if (!long_ || !tasks_->finished()) return;
  tasks_->collect();
  LongRequest l = std::move(*long_);
  long_.reset();
  handling_seq_ = l.seq;
  if (!l.failure->empty()) {
    finish(l.id, control::Refusal::ProgramError,
           fmt::format("the program could not be checked: {}", *l.failure));
  } else {
    l.then();
  }
  handling_seq_ = 0;
}

bool Controller::superseded(std::uint64_t id, bool halts_only) {
  const std::uint64_t after = (halts_only ? halt_seq_ : stop_seq_).load(std::memory_order_relaxed);
  if (handling_seq_ == 0 || after <= handling_seq_) return false;
  finish(id, control::Refusal::Superseded, refusal_text(control::Refusal::Superseded));
  return true;
}

bool Controller::ready_for_job(std::uint64_t id, control::Mode mode, const char* what) {
  if (job_) {
    finish(id, control::Refusal::Busy, "a program is running");
    return false;
  }
  if (servo().mode != mode) {
    finish(id, control::Refusal::WrongMode,
           fmt::format("{} need{} {} mode", what, std::string_view(what).ends_with('s') ? "" : "s",
                       to_string(mode)));
    return false;
  }
  if (servo().state != control::State::Idle) {
    finish(id, not_idle(servo().state), refusal_text(not_idle(servo().state)));
    return false;
  }
  if (servo_config_.homing_required && !servo().all_homed) {
    finish(id, control::Refusal::NotHomed, refusal_text(control::Refusal::NotHomed));
    return false;
  }
  return true;
}

Preflight Controller::preflight_file(const std::string& path, const Pose& at, bool block_delete,
                                     ScanCancel cancel) {
  if (!source_) {
    Preflight p;
    p.diagnostics.error(path, 0, 0, "this controller has no G-code interpreter", "control.program");
    return p;
  }
  return source_->preflight(path, at, {block_delete, cancel}, *check_);
}

Preflight Controller::preflight_canon(const canon::Program& program) {
  Preflight p;
  for (canon::SegmentId id = 0; id < program.size(); ++id) {
    check_->check(program, id, p.diagnostics);
    ++p.summary.moves;
    p.summary.path_length_mm += move_length(program, id);
  }
  check_->finish(p.diagnostics);
  return p;
}

// The preflight is long work: the controller goes on serving the servo while it runs. The file's
// stamp and the source's version are taken before it reads, so that a change made while it reads
// is a change after the check.
void Controller::open_file(std::uint64_t id, const std::string& path) {
  if (job_) return finish(id, control::Refusal::Busy, "a program is running");
  if (servo().mode != control::Mode::Auto)
    return finish(id, control::Refusal::WrongMode, "programs are opened in Auto mode");
  if (superseded(id, true)) return;
  const Pose at = servo().commanded;
  const bool block_delete = block_delete_;
  std::string stamp = file_stamp(path);
  const std::uint64_t version = source_ ? source_->version() : 0;
  auto pf = std::make_shared<Preflight>();
  run_long(
      id,
      [this, pf, path, at, block_delete, cancel = cancel_token()] {
        *pf = preflight_file(path, at, block_delete, cancel);
      },
      [this, id, pf, path, at, block_delete, stamp = std::move(stamp), version]() mutable {
        finish_open(id, path, std::move(*pf), at, block_delete, std::move(stamp), version);
      });
}

void Controller::finish_open(std::uint64_t id, const std::string& path, Preflight pf, const Pose& at,
                             bool block_delete, std::string stamp, std::uint64_t version) {
  if (superseded(id, true)) return;
  if (!pf.ok()) return finish(id, program_refusal(pf.diagnostics), refusal_text(program_refusal(pf.diagnostics)),
                              pf.diagnostics);
  OpenProgram op;
  op.name = path;
  op.path = path;
  op.preflight = pf;
  {
    std::lock_guard lock(out_mutex_);
    open_ = std::move(op);
  }
  open_at_ = at;
  open_block_delete_ = block_delete;
  open_stamp_ = std::move(stamp);
  open_version_ = version;
  open_limits_version_ = limits_version_;
  ControllerEvent e;
  e.kind = ControllerEventKind::ProgramOpened;
  e.text = path;
  log(std::move(e));
  finish(id, control::Refusal::None, {}, std::move(pf.diagnostics));
}

void Controller::open_canon(std::uint64_t id, std::shared_ptr<const canon::Program> program, std::string name) {
  if (job_) return finish(id, control::Refusal::Busy, "a program is running");
  if (servo().mode != control::Mode::Auto)
    return finish(id, control::Refusal::WrongMode, "programs are opened in Auto mode");
  if (!program) return finish(id, control::Refusal::BadValue, "no program given");
  if (superseded(id, true)) return;
  auto pf = std::make_shared<Preflight>();
  run_long(
      id, [this, pf, program] { *pf = preflight_canon(*program); },
      [this, id, pf, program, name = std::move(name)]() mutable {
        if (superseded(id, true)) return;
        if (!pf->ok())
          return finish(id, program_refusal(pf->diagnostics), refusal_text(program_refusal(pf->diagnostics)),
                        pf->diagnostics);
        OpenProgram op;
        op.name = name;
        op.program = std::move(program);
        op.preflight = *pf;
        {
          std::lock_guard lock(out_mutex_);
          open_ = std::move(op);
        }
        open_at_ = servo().commanded;
        open_limits_version_ = limits_version_;
        ControllerEvent e;
        e.kind = ControllerEventKind::ProgramOpened;
        e.text = name;
        log(std::move(e));
        finish(id, control::Refusal::None, {}, std::move(pf->diagnostics));
      });
}

void Controller::mdi(std::uint64_t id, const std::string& line) {
  if (!ready_for_job(id, control::Mode::Mdi, "MDI lines")) return;
  if (!source_)
    return finish(id, control::Refusal::ProgramError, "this controller has no G-code interpreter");
  start_job(id, JobKind::Mdi, line, control::Mode::Mdi, source_->mdi(line, servo().commanded));
}

void Controller::cycle_start(std::uint64_t id, const Request& r) {
  std::optional<OpenProgram> op = open_program();
  // A program open and the machine idle in Manual or MDI (after homing, a jog, an MDI line): the
  // mode follows, as the operator means to run it (docs/controller.md, "Cycle start").
  const bool mode_follows =
      !job_ && op && servo().mode != control::Mode::Auto && servo().state == control::State::Idle;
  if (job_ ||
      (servo().mode != control::Mode::Auto && !mode_follows)) {  // the servo continues (M0, hold) or says no
    const std::optional<control::Command> c = to_command(r);
    return forward(id, *c);
  }
  if (!op)
    return finish(id, control::Refusal::NoProgram,
                  "no program is open: open one (the Program screen, or open FILE), then cycle start");
  if (!ready_for_job(id, mode_follows ? servo().mode : control::Mode::Auto, "programs")) return;
  if (!features_allow_start(id, {JobKind::Program, op->name})) return;
  if (op->program) {
    // Checked when opened, unless the machine stands elsewhere or its limits changed since.
    const bool same_start =
        op->program->start() == servo().commanded && open_limits_version_ == limits_version_;
    start_job(id, JobKind::Program, op->name, control::Mode::Auto,
              canon_stream(op->program, servo().commanded), same_start);
    return;
  }
  // The preflight holds for the position, the switches and the file it was made with: anything
  // else, and the program is checked again (long work) before it may start.
  const Pose at = servo().commanded;
  const bool block_delete = block_delete_;
  if (at != open_at_ || block_delete != open_block_delete_ || file_stamp(op->path) != open_stamp_ ||
      source_->version() != open_version_ || open_limits_version_ != limits_version_) {
    std::string stamp = file_stamp(op->path);
    const std::uint64_t version = source_->version();
    auto pf = std::make_shared<Preflight>();
    run_long(
        id,
        [this, pf, path = op->path, at, block_delete, cancel = cancel_token()] {
          *pf = preflight_file(path, at, block_delete, cancel);
        },
        [this, id, pf, path = op->path, at, block_delete, stamp = std::move(stamp), version]() mutable {
          start_checked(id, path, std::move(*pf), at, block_delete, std::move(stamp), version);
        });
    return;
  }
  // Up to its first sync point the program is the one the preflight checked.
  start_job(id, JobKind::Program, op->name, control::Mode::Auto,
            source_->execute(op->path, at, {block_delete}), true);
}

// The open program checked again for a cycle start: it starts if nothing changed meanwhile (only
// the urgent lane's stops can act while it is checked, and a stop sent after the start drops it).
void Controller::start_checked(std::uint64_t id, const std::string& path, Preflight pf, const Pose& at,
                               bool block_delete, std::string stamp, std::uint64_t version) {
  if (superseded(id, false)) return;
  if (!pf.ok())
    return finish(id, program_refusal(pf.diagnostics), refusal_text(program_refusal(pf.diagnostics)),
                  pf.diagnostics);
  open_at_ = at;
  open_block_delete_ = block_delete;
  open_stamp_ = std::move(stamp);
  open_version_ = version;
  open_limits_version_ = limits_version_;
  std::string name;
  {
    std::lock_guard lock(out_mutex_);
    if (!open_ || open_->path != path)
      return finish(id, control::Refusal::NoProgram, refusal_text(control::Refusal::NoProgram));
    open_->preflight = std::move(pf);
    name = open_->name;
  }
  // (The cycle start it answers may have been pressed in Manual or MDI: the mode follows.)
  if (!ready_for_job(id, servo().mode, "programs")) return;
  if (servo().commanded != at)
    return finish(id, control::Refusal::StartMismatch,
                  "the machine moved while the program was checked: start it again");
  start_job(id, JobKind::Program, name, control::Mode::Auto, source_->execute(path, at, {block_delete}),
            true);
}

void Controller::run_auxiliary(std::uint64_t id, const requests::RunAuxiliary& r) {
  if (!ready_for_job(id, control::Mode::Auto, "auxiliary programs")) return;
  const std::string name = r.name.empty() ? (r.path.empty() ? "auxiliary" : r.path) : r.name;
  if (!features_allow_start(id, {JobKind::Auxiliary, name})) return;
  if (superseded(id, false)) return;
  const Pose at = servo().commanded;
  const bool block_delete = block_delete_;
  auto pf = std::make_shared<Preflight>();
  run_long(
      id,
      [this, pf, program = r.program, path = r.path, at, block_delete, cancel = cancel_token()] {
        *pf = program ? preflight_canon(*program) : preflight_file(path, at, block_delete, cancel);
      },
      [this, id, pf, program = r.program, path = r.path, name, at, block_delete] {
        if (superseded(id, false)) return;
        if (!pf->ok())
          return finish(id, program_refusal(pf->diagnostics), refusal_text(program_refusal(pf->diagnostics)),
                        pf->diagnostics);
        if (!ready_for_job(id, control::Mode::Auto, "auxiliary programs")) return;
        if (servo().commanded != at)
          return finish(id, control::Refusal::StartMismatch,
                        "the machine moved while the program was checked: start it again");
        if (program)
          return start_job(id, JobKind::Auxiliary, name, control::Mode::Auto, canon_stream(program, at),
                           program->start() == at);
        start_job(id, JobKind::Auxiliary, name, control::Mode::Auto,
                  source_->execute(path, at, {block_delete}), true);
      });
}

// Every feature's check before a start (Feature::allow_start); the first that says no refuses it.
bool Controller::features_allow_start(std::uint64_t id, const StartCheck& start) {
  for (auto& [name, f] : features_) {
    std::string why;
    bool ok = true;
    try {
      ok = f->allow_start(start, *this, &why);
    } catch (const std::exception& ex) {
      ok = false;
      why = ex.what();
    }
    if (!ok) {
      finish(id, control::Refusal::FeatureCheck,
             fmt::format("{}: {}", name, why.empty() ? refusal_text(control::Refusal::FeatureCheck) : why));
      return false;
    }
  }
  return true;
}

// Whether every feature lets the job read on past a sync point (Feature::allow_continue).
bool Controller::features_allow_continue(const SyncCheck& sync) {
  for (auto& [name, f] : features_) {
    bool ok = true;
    try {
      ok = f->allow_continue(sync, *this);
    } catch (const std::exception& ex) {
      // A feature that fails cannot vouch for what follows: hold, and say so once.
      if (held_by_ != name)
        note(Severity::Error, "control.feature",
             fmt::format("{} failed at the {}: {}", name, to_string(sync.kind), ex.what()));
      ok = false;
    }
    if (!ok) {
      held_by_ = name;
      return false;
    }
  }
  held_by_.clear();
  return true;
}

void Controller::resume_program(std::uint64_t id, const requests::ResumeProgram& r) {
  std::optional<OpenProgram> op = open_program();
  if (!op) return finish(id, control::Refusal::NoProgram, refusal_text(control::Refusal::NoProgram));
  if (op->path.empty())
    return finish(id, control::Refusal::BadValue, "only a program file can be resumed at a segment");
  if (!ready_for_job(id, control::Mode::Auto, "programs")) return;
  if (!features_allow_start(id, {JobKind::Program, op->name})) return;
  if (superseded(id, false)) return;
  const Pose at = servo().commanded;
  const ScanCancel cancel = cancel_token();
  // Held in a shared slot: the task reads it, then the job takes it.
  auto stream = std::make_shared<std::unique_ptr<ProgramStream>>(
      source_->resume(op->path, r.program_start.value_or(open_at_), at, r.segment, {block_delete_, cancel}));
  if (!*stream)
    return finish(id, control::Refusal::BadValue,
                  "this controller's program source cannot resume at a segment");
  // The replay up to the segment (long work): a program that cannot get there starts nothing.
  run_long(
      id,
      [stream, cancel] {
        ProgramStream& s = **stream;
        while (s.state() == StreamState::Reading && s.program().empty() && !cancel.requested()) s.read(1);
      },
      [this, id, stream, at, name = op->name] {
        if (superseded(id, false)) return;
        if (!ready_for_job(id, control::Mode::Auto, "programs")) return;
        if (servo().commanded != at)
          return finish(id, control::Refusal::StartMismatch,
                        "the machine moved while the program was replayed: start it again");
        // Every move is checked before it runs (the preflight's moves began elsewhere).
        start_job(id, JobKind::Program, name, control::Mode::Auto, std::move(*stream), false, true);
      });
}

void Controller::feature(std::uint64_t id, const requests::Feature& r) {
  const auto it = features_.find(r.feature);
  if (it == features_.end())
    return finish(id, control::Refusal::BadValue, fmt::format("there is no feature named '{}'", r.feature));
  Outcome o;
  handling_ = id;
  deferred_ = false;
  try {
    o = it->second->handle(r, *this);
  } catch (const std::exception& ex) {
    deferred_ = false;  // a feature that fails answers now, deferred or not
    o.accepted = false;
    o.refusal = control::Refusal::BadValue;
    o.message = fmt::format("{}: {}", r.feature, ex.what());
  }
  handling_ = 0;
  if (!deferred_) answer(id, std::move(o));
}

std::uint64_t Controller::defer() {
  if (handling_ == 0) throw std::logic_error("FeatureHost::defer() outside Feature::handle");
  deferred_ = true;
  return handling_;
}

void Controller::answer_after(std::function<void()> work, std::function<Outcome()> then) {
  const std::uint64_t id = defer();
  run_long(id, std::move(work), [this, id, then = std::move(then)] { answer(id, then()); });
}

void Controller::answer(std::uint64_t id, Outcome o) {
  finish(id,
         o.accepted ? control::Refusal::None
                    : (o.refusal == control::Refusal::None ? control::Refusal::BadValue : o.refusal),
         o.message, std::move(o.diagnostics));
}

// Features whose work runs on threads of their own look whether it is done.
void Controller::poll_features() {
  for (auto& [name, f] : features_) {
    try {
      f->poll(*this);
    } catch (const std::exception& ex) {
      note(Severity::Error, "control.feature", fmt::format("{}: {}", name, ex.what()));
    }
  }
}

// --- jobs ------------------------------------------------------------------------------------

void Controller::start_job(std::uint64_t id, JobKind kind, std::string name, control::Mode mode,
                           std::unique_ptr<ProgramStream> stream, bool prechecked, bool resumes) {
  if (servo().mode != mode) {
    // A program started from Manual or MDI: the mode follows, ahead of the StartRun in the queue.
    control::Command m;
    m.kind = control::CommandKind::SetMode;
    m.mode = mode;
    m.id = new_id();
    m.seq = handling_seq_;
    if (!send(m)) return finish(id, control::Refusal::Busy, "the servo's command queue is full");
  }
  detail::JobHost host;
  host.channels = channels_;
  host.servo = &servo_config_;
  host.limits = &limits_;
  host.planner = &planner_config_;
  host.check = check_.get();
  host.readahead_moves = static_cast<std::size_t>(std::max(1, profile_.interpreter.readahead_moves));
  host.readahead_s = profile_.interpreter.readahead_s;
  host.prechecked = prechecked;
  // A feature's auxiliary moves (a retrace's way to C) stand between an interrupted program and
  // its resume: they keep its process state as well.
  host.continues = resumes || kind == JobKind::Auxiliary;
  host.next_command_id = [this] { return new_id(); };
  host.log = [this](ControllerEvent e) { log(std::move(e)); };
  host.send = [this](const control::Command& c) { return send(c); };
  host.request_seq = handling_seq_;
  host.next_run_id = [this] { return ++run_counter_; };
  host.may_continue = [this](const SyncCheck& c) { return features_allow_continue(c); };
  auto job = std::make_unique<detail::Job>(kind, ++job_counter_, name, mode, std::move(stream), std::move(host));
  // A program's interpreter sets its offsets as it starts; the MDI session's keeps its own; a
  // canonical program (an approach move) has none: the ones shown stay.
  job->set_initial_offsets(kind == JobKind::Mdi ? mdi_offsets_ : published_.offsets);
  Diagnostics d;
  if (!job->start(id, d)) {
    const control::Refusal why = program_refusal(d);
    return finish(id, why, refusal_text(why), std::move(d));
  }
  job_ = std::move(job);
  ControllerEvent e;
  e.kind = ControllerEventKind::JobStarted;
  e.job = kind;
  e.job_id = job_->id();
  e.text = name;
  log(std::move(e));
  // The answer is the servo's to the StartRun sent with this id.
}

void Controller::end_job() {
  const detail::Job& j = *job_;
  for (const Diagnostic& d : j.errors().items()) {
    note(d.severity, d.code, d.format());
  }
  if (j.end_reason() == JobEnd::Finished) ++runs_finished_;
  {
    // The interpreter's offsets stay in effect after the job: the status keeps showing them.
    std::lock_guard lock(out_mutex_);
    published_.offsets = j.latest_offsets();
    published_.distance_to_go = Pose{};
  }
  if (j.kind() == JobKind::Mdi) mdi_offsets_ = j.latest_offsets();
  ControllerEvent e;
  e.kind = ControllerEventKind::JobEnded;
  e.job = j.kind();
  e.job_id = j.id();
  e.end = j.end_reason();
  e.segment = j.job_segment(servo().segment);
  e.text = fmt::format("{} {}", j.name(), to_string(j.end_reason()));
  e.severity = j.end_reason() == JobEnd::Error ? Severity::Error : Severity::Note;
  log(std::move(e));
  retired_ = std::move(job_);
}

// --- status ----------------------------------------------------------------------------------

void Controller::publish() {
  std::lock_guard lock(out_mutex_);
  ControllerStatus& p = published_;
  if (open_ ? p.program_name != open_->name : !p.program_name.empty()) p.program_name = open_ ? open_->name : "";
  p.program_moves = open_ ? open_->preflight.summary.moves : 0;
  p.program_length_mm = open_ ? open_->preflight.summary.path_length_mm : 0;
  p.run_active = job_ != nullptr;
  const control::ServoStatus& s = servo();
  p.servo = s;  // FeatureHost::current_status() is this, servo snapshot included
  if (job_) {
    const bool same_run = s.run_id == job_->run_id();
    p.job = job_->kind();
    p.job_id = job_->id();
    if (p.job_name != job_->name()) p.job_name = job_->name();
    // The move the machine is on: a block the planner joined from several lines counts its
    // offset from the first one's start (a hold, a retrace's A and a breakpoint need the move).
    const canon::MoveOffset at =
        same_run ? canon::along_joined(job_->program(), s.segment, s.segment_offset) : canon::MoveOffset{};
    p.run_segment = same_run ? job_->job_segment(at.move) : 0;
    p.segment_offset = at.offset_mm;
    p.progress = job_->kind() == JobKind::Program && p.program_moves > 0
                     ? std::min(1.0, static_cast<double>(p.run_segment) / static_cast<double>(p.program_moves))
                     : 0.0;
    p.interpreter_moves = job_->moves_read();
    p.sync_wait = job_->sync_wait();
    update_locations();
    update_offsets(same_run);
  } else {
    p.job = JobKind::None;
    p.run_segment = 0;
    p.segment_offset = 0;
    p.progress = 0;
    p.sync_wait = SyncKind::None;
    p.distance_to_go = Pose{};
  }
  // What the run waits for, in words: only when one of the things it is made of changed.
  const WaitKey key{s.state, s.wait, s.stop_reason, p.sync_wait, s.line, s.context, job_ != nullptr};
  if (!(key == wait_key_)) {
    p.wait_text = wait_text();
    wait_key_ = key;
  }
  if (s.fault.kind == control::FaultKind::None) {
    if (!p.fault_text.empty()) p.fault_text.clear();
  } else if (s.fault.tick != described_fault_tick_) {
    p.fault_text = describe(s.fault);
    described_fault_tick_ = s.fault.tick;
  }
  p.runs_finished = runs_finished_;
  p.limits_version = limits_version_;
  p.block_delete = block_delete_;
}

// The offsets of the move at the commanded position, and what is left of that move.
void Controller::update_offsets(bool same_run) {
  ControllerStatus& p = published_;
  const control::ServoStatus& s = servo();
  p.distance_to_go = Pose{};
  if (!same_run) return;
  p.offsets = job_->offsets_at(s.segment);
  if (!s.run_active) return;
  if (const std::optional<Pose> end = job_->move_end(s.segment)) {
    for (int i = 0; i < kAxisCount; ++i) p.distance_to_go[i] = (*end)[i] - s.commanded[i];
  }
}

// Strings, so only when they change: the source at the commanded position, and (at most every
// kLocationRefreshS of servo time) where the interpreter reads.
void Controller::update_locations() {
  ControllerStatus& p = published_;
  const control::ServoStatus& s = servo();
  if (s.run_id == job_->run_id() && (s.context != located_context_ || s.line != located_line_ || s.run_id != located_run_)) {
    p.location = job_->locate_servo(s.context, s.line);
    located_context_ = s.context;
    located_line_ = s.line;
    located_run_ = s.run_id;
  }
  const bool waiting = p.sync_wait != SyncKind::None;
  if (interpreter_seen_ == ~std::uint64_t{0} || s.tick >= interpreter_seen_ + location_every_ || waiting) {
    p.interpreter = job_->interpreter_location();
    p.sync_location = waiting ? job_->sync_location() : SourceLocation{};
    interpreter_seen_ = s.tick;
  }
}

std::string Controller::wait_text() const {
  const control::ServoStatus& s = servo();
  if (!job_) return {};
  if (s.state == control::State::Stopped) {
    const char* why = s.stop_reason == control::StopReason::SingleBlock    ? "single block"
                      : s.stop_reason == control::StopReason::OptionalStop ? "M1"
                                                                           : "M0";
    return fmt::format("the operator's cycle start ({} at {})", why, to_string(published_.location));
  }
  if (s.state == control::State::Held) return "the operator's resume (feed hold)";
  if (job_->held_at_sync() && !held_by_.empty())
    return fmt::format("the {} to let the program go on past the {} (see its note)", held_by_,
                       to_string(job_->sync_wait()));
  for (const auto& t : texts_)  // a feature's stage holds the run
    if (std::optional<std::string> w = t->wait_text(s)) return *w;
  switch (s.wait) {
    case control::Wait::None:
      return {};
    case control::Wait::Dwell:
      return "a dwell";
    case control::Wait::Spindle:
      return "the spindle to reach its speed";
    case control::Wait::ToolChanger:
      return fmt::format("the tool changer (T{})", s.prepared_tool);
    case control::Wait::ManualToolChange:
      return fmt::format("the operator to put tool T{} in the spindle and confirm", s.prepared_tool);
    case control::Wait::Input:
      return "an input (M66)";
    case control::Wait::Orient:
      return "the spindle orientation (M19)";
    case control::Wait::Probe:
      return "the probe";
    case control::Wait::Starved:
      if (published_.sync_wait != SyncKind::None)
        return fmt::format("the interpreter, at the {} of {}", to_string(published_.sync_wait),
                           to_string(published_.sync_location));
      return "the planner";
    case control::Wait::HandAxis:
      return "the operator at a hand-fed axis";
    case control::Wait::Interlock: {
      const auto& texts = profile_.interlocks.rule_texts;
      const auto rule = static_cast<std::size_t>(s.interlock_rule);
      return fmt::format("the interlock \"{}\" to let the spindle start",
                         s.interlock_rule >= 0 && rule < texts.size() ? texts[rule] : std::string("?"));
    }
  }
  return {};
}

// --- observers and the log -------------------------------------------------------------------

void Controller::log(ControllerEvent e) {
  e.tick = servo().tick;
  log_.append(e);
}

void Controller::tell_observers() {
  if (observers_.empty()) return;
  const std::uint64_t last = log_.last();
  for (Attached& a : observers_) {
    try {
      if (a.cursor < last) {
        std::uint64_t lost = 0;
        for (const ControllerEvent& e : log_.read_after(a.cursor, last - a.cursor, &lost)) a.observer->on_event(e);
        a.cursor = last;
      }
      if (a.options.status_period_s > 0 && servo().tick >= a.next_status) {
        a.observer->on_status(status());
        a.next_status = servo().tick + static_cast<std::uint64_t>(a.options.status_period_s / servo_config_.period_s);
      }
    } catch (const std::exception& ex) {
      a.observer.reset();
      note(Severity::Error, "control.observer", fmt::format("an observer failed and was detached: {}", ex.what()));
    }
  }
  std::erase_if(observers_, [](const Attached& a) { return !a.observer; });
}

void Controller::note(Severity s, std::string code, std::string text) {
  ControllerEvent e;
  e.kind = ControllerEventKind::Note;
  e.severity = s;
  e.code = std::move(code);
  e.text = std::move(text);
  log(std::move(e));
}

void Controller::finish(std::uint64_t id, control::Refusal refusal, std::string message, Diagnostics diags) {
  ControllerEvent e;
  e.kind = ControllerEventKind::Answer;
  e.request_id = id;
  e.accepted = refusal == control::Refusal::None;
  e.code = refusal_code(refusal);
  e.severity = e.accepted ? Severity::Note : Severity::Error;
  {
    std::lock_guard lock(out_mutex_);
    KeptOutcome& k = outcomes_[id % outcomes_.size()];
    e.text = message.empty() ? refusal_text(refusal) : std::move(message);
    if (k.id <= id) {  // a later request's answer already there: this one is older than any kept
      k.id = id;
      k.outcome.accepted = refusal == control::Refusal::None;
      k.outcome.refusal = refusal;
      k.outcome.message = e.text;
      k.outcome.diagnostics = std::move(diags);
    }
  }
  log(std::move(e));
}

std::string Controller::interlock_text(const control::ServoEvent& e) const {
  const auto& texts = profile_.interlocks.rule_texts;
  const std::string rule = e.action < texts.size() ? texts[e.action] : std::string("?");
  const char* what = e.command == control::CommandKind::SpindleOff ? "stopped the spindle"
                     : e.command == control::CommandKind::Coolant  ? "stopped the coolant"
                     : e.command == control::CommandKind::FeedHold ? "held the motion"
                     : e.command == control::CommandKind::JogStop  ? "stopped the jog"
                                                                   : "e-stopped the machine";
  return fmt::format("interlock \"{}\" {}", rule, what);
}

// What a seek found, in the units of the axis; the rest position is in the status.
std::string Controller::seek_text(const control::ServoEvent& e) const {
  const char axis = e.axis >= 0 && e.axis < kAxisCount ? kAxisLetters[static_cast<std::size_t>(e.axis)] : '?';
  const control::ServoStatus& s = servo();
  for (int j = 0; j < servo_config_.joint_count; ++j) {
    const control::JointConfig& jc = servo_config_.joints[static_cast<std::size_t>(j)];
    if (jc.axis != e.axis) continue;
    const char* unit = jc.rotary ? "deg" : "mm";
    const control::LimitSeekStatus& st = s.seek[static_cast<std::size_t>(j)];
    if (e.action != 1)
      return fmt::format("{}: the seek of its limit switch stopped at {:.4f} {}", axis, e.value, unit);
    return fmt::format("{}'s {} limit switch trips at {:.4f} {}; the axis backed off to {:.4f} {}", axis,
                       st.direction > 0 ? "+" : "−", e.value, unit, st.rest_at, unit);
  }
  return fmt::format("{}: limit seek at {:.4f}", axis, e.value);
}

std::string Controller::describe(const control::Fault& f) const {
  for (const auto& t : texts_)  // a feature's stage raised it
    if (std::optional<std::string> text = t->fault_text(f, profile_, servo_config_)) return *text;
  const char axis = f.axis >= 0 && f.axis < kAxisCount ? kAxisLetters[static_cast<std::size_t>(f.axis)] : '?';
  const control::JointConfig* jc = nullptr;
  for (int j = 0; j < servo_config_.joint_count; ++j) {
    if (servo_config_.joints[static_cast<std::size_t>(j)].axis == f.axis)
      jc = &servo_config_.joints[static_cast<std::size_t>(j)];
  }
  const char* unit = jc != nullptr && jc->rotary ? "deg" : "mm";
  switch (f.kind) {
    case control::FaultKind::None:
      return "";
    case control::FaultKind::LimitSwitch:
      return fmt::format("limit switch on {} tripped at {:.4f} {}", axis, f.value, unit);
    case control::FaultKind::AmpFault:
      return fmt::format("the {} drive reports a fault (at {:.4f} {})", axis, f.value, unit);
    case control::FaultKind::FollowingError:
      return fmt::format("following error on {}: {:.4f} {}, more than the {} {} allowed", axis, f.value, unit,
                         f.limit, unit);
    case control::FaultKind::SoftLimit:
      return fmt::format("{} was commanded to {:.4f} {}, beyond its soft limit of {} {}", axis, f.value, unit,
                         f.limit, unit);
    case control::FaultKind::PowerLoss:
      return fmt::format(
          "power failure: mains lost or running on the UPS (DC link {:.0f} V); the motion was "
          "stopped on the path",
          f.value);
    case control::FaultKind::Homing:
      return fmt::format(
          "homing {} failed at {:.4f} {}: a limit switch, or the home sensor not on the "
          "deceleration dog",
          axis, f.value, unit);
    case control::FaultKind::Stall:
      return fmt::format("the {} stepper stalled at {:.4f} {}: steps were lost, home it again", axis, f.value,
                         unit);
    case control::FaultKind::SeekNoSwitch:
      return fmt::format(
          "seeking its limit, {} went {:.4f} {} (its soft limit {} {} and the overtravel) without the limit "
          "switch tripping: check the switch and its wiring, then home {} again",
          axis, f.value, unit, f.limit, unit, axis);
    case control::FaultKind::ProcessAlarm:
      return detail::alarm_text(profile_.alarms, static_cast<std::size_t>(f.axis), f.value, f.value < f.limit,
                                false);
    default:  // a feature's stage's, described by the feature
      break;
  }
  return "fault";
}

}  // namespace opencnc::controller
