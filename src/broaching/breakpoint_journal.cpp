// SPDX-License-Identifier: GPL-3.0-or-later
// BreakpointJournal: the record built on the controller's thread at the power-fail signal and
// at rest, made durable on the writer thread (hash of the program, journal write, modal digest).
#include "opencnc/broaching/breakpoint_journal.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "opencnc/broaching/modal_digest.hpp"
#include "opencnc/canon/move_length.hpp"
#include "opencnc/controller/gcode_source.hpp"

namespace opencnc::recovery {

using controller::ControllerEventKind;

namespace {

/// The record's move: `move` of the run's window `p` (the run's moves from `first_move` on).
/// Returns its path length as the planner counts it (the status's offset counts along it).
double take_move(BreakpointRecord& r, const canon::Program& p, canon::SegmentId move,
                 std::uint64_t first_move) {
  r.job_move = first_move + move;
  if (move < p.first_held_move() || move >= p.size()) return 0;
  r.segment = p.segment_of(move);
  r.move_kind = static_cast<std::uint8_t>(p.move(move).kind);
  r.move_start = p.start_of(move);
  r.move_end = p.end(move);
  r.line = p.move(move).line;
  r.source_file = p.sources().file(p.file_of(move));
  return canon::planned_length(p, move);
}

/// The writer's SCHED_FIFO priority where the process may have one: below the servo thread's (80,
/// control::RealtimeClock), above everything that is not real-time. Under load the time from the
/// signal to the durable record was the writer waiting for a core, not the disk (docs/broaching.md).
constexpr int kWriterPriority = 70;

/// The calling thread to SCHED_FIFO at `priority`, or back to SCHED_OTHER (0); false where not
/// permitted (no CAP_SYS_NICE, no RLIMIT_RTPRIO): the thread then stays as it was.
bool schedule_this_thread(int priority) {
  sched_param param{};
  param.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), priority > 0 ? SCHED_FIFO : SCHED_OTHER, &param) == 0;
}

/// Runs `f` at normal CPU and I/O priority when the writer holds raised ones (hashing a program,
/// replaying it for the digest: no emergency, and long for a large file), then raises them again.
template <typename F>
void at_normal_priority(bool fifo, bool rt_io, F&& f) {
  if (fifo) schedule_this_thread(0);
  if (rt_io) reset_io_priority();
  f();
  if (rt_io) raise_io_priority();
  if (fifo) schedule_this_thread(kWriterPriority);
}

}  // namespace

std::shared_ptr<BreakpointJournal> BreakpointJournal::open(
    const std::string& dir, std::shared_ptr<controller::GcodeProgramSource> source, std::string* error) {
  std::unique_ptr<Journal> j = Journal::open(dir, error);
  if (!j) return nullptr;
  return std::shared_ptr<BreakpointJournal>(new BreakpointJournal(std::move(j), std::move(source)));
}

BreakpointJournal::BreakpointJournal(std::unique_ptr<Journal> journal,
                                     std::shared_ptr<controller::GcodeProgramSource> source)
    : journal_(std::move(journal)), source_(std::move(source)) {
  // A record left by an earlier run (the power came back): what recovery offers.
  if (const std::optional<JournalRecord> raw = journal_->read()) written_ = decode(raw->payload, &error_);
  writer_status_ = journal_->how() + "; writer thread starting";
  writer_ = std::thread([this] { writer_loop(); });
}

BreakpointJournal::~BreakpointJournal() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  writer_.join();
}

void BreakpointJournal::on_event(const controller::ControllerEvent& e) {
  recovery_event(e);
  if (e.kind != ControllerEventKind::ProgramOpened || host_ == nullptr) return;
  // Resume replays from where the program was placed when it was opened (the controller's rule);
  // a program resumed after a power failure keeps its first start.
  path_ = e.text;
  program_start_ = phase_ == RecoveryPhase::Opening || phase_ == RecoveryPhase::RunningIn ||
                           phase_ == RecoveryPhase::Resuming
                       ? recovering_.program_start
                       : host_->current_status().servo.commanded;
  options_.reset();
  if (source_) {
    source_->profile_changed(host_->profile());  // the conditions an admin changed since
    options_ = source_->options_for(path_, {});
  }
  stopping_ = completed_ = false;
  Work w;
  w.record.program_path = path_;
  w.hash_only = true;
  post(std::move(w));
}

void BreakpointJournal::on_status(const controller::ControllerStatus& s) {
  if (!stopping_) {
    if (s.servo.mains_ok && !s.servo.on_battery) before_ = s.servo;
    if (s.run_active && s.job == controller::JobKind::Program) {
      job_move_ = s.run_segment;
      segment_offset_ = s.segment_offset;
    }
    return;
  }
  if (s.run_active && s.job == controller::JobKind::Program) {
    job_move_ = s.run_segment;
    segment_offset_ = s.segment_offset;
  }
  // The servo faults (power-loss) once the motion has come to rest: the record is complete.
  if (!completed_ && s.servo.state == control::State::Faulted) complete_record();
}

void BreakpointJournal::on_trace(const control::TraceSample& s, const controller::TraceContext& c) {
  if (stopping_ && !completed_ && s.state != control::State::Faulted) {
    // Where the stop has brought the axes so far (the drives are disabled once it rests, and
    // the command then follows the feedback: the record keeps the last period before that).
    record_.commanded = s.commanded;
    record_.actual = s.actual;
    record_.rest_time_s = static_cast<double>(s.tick) * period_s();
    // The stop may carry the machine on into the next of the lines the planner joined.
    if (c.program != nullptr && job_move_ > record_.job_move && job_move_ >= c.first_move &&
        job_move_ - c.first_move <= s.segment_last)
      move_length_mm_ = take_move(record_, *c.program, job_move_ - c.first_move, c.first_move);
    return;
  }
  if (!s.power_stop || stopping_ || c.job != controller::JobKind::Program || c.program == nullptr) return;
  begin_record(s, c);
}

// The first period of the stop: everything but where the motion will rest.
void BreakpointJournal::begin_record(const control::TraceSample& s, const controller::TraceContext& c) {
  const Clock::time_point signal = Clock::now();
  stopping_ = true;
  completed_ = false;
  const canon::Program& p = *c.program;
  BreakpointRecord& r = record_;
  r = {};
  r.valid = true;
  r.stage = BreakpointStage::Stopping;
  r.program_path = path_;
  r.program_start = program_start_;
  // The move the machine is on: the status's (the servo's segment is the first of the lines the
  // planner joined into the block there; the status counts the offset on into the one it is on).
  canon::SegmentId move = s.segment;
  if (job_move_ >= c.first_move && job_move_ - c.first_move > move &&
      job_move_ - c.first_move <= s.segment_last)
    move = job_move_ - c.first_move;
  const double length = take_move(r, p, move, c.first_move);
  r.commanded = s.commanded;
  r.actual = s.actual;
  r.segment_offset_mm = job_move_ == r.job_move ? segment_offset_ : 0.0;
  r.tool = before_.tool;
  r.spindle_rpm = before_.spindle_rpm;
  r.spindle_direction = before_.spindle_direction == machine::SpindleDirection::Clockwise          ? 1
                        : before_.spindle_direction == machine::SpindleDirection::Counterclockwise ? -1
                                                                                                   : 0;
  r.flood = before_.flood;
  r.mist = before_.mist;
  const control::CouplingStatus& k = before_.coupling;
  r.coupling = {static_cast<std::uint8_t>(k.kind),
                k.master_axis,
                k.slave_axis,
                k.table,
                k.pitch_mm,
                k.pitch_rate,
                k.master_origin,
                k.slave_origin};
  r.signal_time_s = static_cast<double>(s.tick) * period_s();
  move_length_mm_ = length;
  r.move_remaining_mm = std::max(0.0, length - r.segment_offset_mm);
  Work w;
  w.record = r;
  w.signal = signal;
  post(std::move(w));
}

// At rest: where the axes stand and how much of the interrupted move is left.
void BreakpointJournal::complete_record() {
  completed_ = true;
  BreakpointRecord& r = record_;
  r.stage = BreakpointStage::AtRest;
  // The status's offset is along the record's move, unless the stop crossed into the next joined
  // line in its last period: then the record's move was run to its end.
  r.segment_offset_mm = job_move_ == r.job_move ? segment_offset_ : move_length_mm_;
  r.move_remaining_mm = std::max(0.0, move_length_mm_ - r.segment_offset_mm);
  Work w;
  w.record = r;
  w.digest = options_.has_value();
  if (options_) w.options = *options_;
  post(std::move(w));
}

void BreakpointJournal::post(Work w) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(w));
  }
  wake_.notify_one();
}

void BreakpointJournal::flush() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

std::optional<BreakpointRecord> BreakpointJournal::last_written() const {
  std::lock_guard lock(mutex_);
  return written_;
}

std::vector<double> BreakpointJournal::latencies_ms() const {
  std::lock_guard lock(mutex_);
  return latencies_ms_;
}

std::string BreakpointJournal::last_error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

std::string BreakpointJournal::writer_status() const {
  std::lock_guard lock(mutex_);
  return writer_status_;
}

void BreakpointJournal::set_writer_status(bool fifo, bool rt_io) {
  std::string status =
      fmt::format("{}; writer thread {}; I/O priority {}", journal_->how(),
                  fifo ? fmt::format("SCHED_FIFO {}", kWriterPriority) : "normal (SCHED_FIFO not permitted)",
                  rt_io ? "real-time class" : "normal (the real-time class not permitted)");
  std::lock_guard lock(mutex_);
  writer_status_ = std::move(status);
}

// Takes the queue in one piece: a newer record makes an older one not yet written moot (but the
// older one's signal time still counts for the latency of the first durable record).
void BreakpointJournal::writer_loop() {
  // Where permitted (else a normal thread, and the status says so): the CPU when the signal comes,
  // and the I/O scheduler's first place for the record's write (docs/broaching.md).
  fifo_ = schedule_this_thread(kWriterPriority);
  rt_io_ = raise_io_priority();
  set_writer_status(fifo_, rt_io_);
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty() && stop_) return;
    std::vector<Work> batch;
    batch.swap(queue_);
    busy_ = true;
    lock.unlock();
    std::optional<Clock::time_point> signal;
    std::optional<Work> last;
    for (Work& w : batch) {
      if (w.hash_only) {  // a program just opened: no emergency, and a huge file takes a while
        hashed_path_ = w.record.program_path;
        at_normal_priority(fifo_, rt_io_, [&] { hash_ = hash_file(hashed_path_).value_or(FileHash{}); });
        continue;
      }
      if (w.signal && !signal) signal = w.signal;
      last = std::move(w);
    }
    if (last) {
      if (signal) last->signal = signal;
      write_one(*last);
    }
    lock.lock();
    busy_ = false;
    if (queue_.empty()) idle_.notify_all();
  }
}

// One record made durable; the first of a stop times its latency; the completed one is then
// written again with the modal digest (the replay may take a while: the record is safe first).
void BreakpointJournal::write_one(Work& w) {
  BreakpointRecord& r = w.record;
  if (r.program_path != hashed_path_) {
    hashed_path_ = r.program_path;
    hash_ = hash_file(hashed_path_).value_or(FileHash{});
  }
  r.program_hash = hash_.hash;
  r.program_size = hash_.size;
  std::string error;
  const JournalSync before = journal_->sync();
  bool ok = journal_->write(encode(r), &error);
  const Clock::time_point durable = Clock::now();
  if (journal_->sync() != before) set_writer_status(fifo_, rt_io_);  // the file system refused a way
  if (ok && w.digest) {
    // The replay is no emergency (the record is durable) and may be long: not at real-time priority.
    std::string why;
    std::optional<std::uint64_t> d;
    at_normal_priority(fifo_, rt_io_, [&] {
      d = modal_digest_at(w.options, r.program_path, r.program_start, r.segment, &why);
    });
    if (d) {
      r.modal_digest = *d;
      ok = journal_->write(encode(r), &error);
    } else {
      error = "modal digest: " + why;  // the record stands without it (resume then checks nothing)
    }
  }
  std::lock_guard lock(mutex_);
  if (ok) written_ = r;
  error_ = error;
  if (ok && w.signal) {
    latencies_ms_.push_back(std::chrono::duration<double, std::milli>(durable - *w.signal).count());
  }
}

controller::Outcome BreakpointJournal::handle(const controller::requests::Feature& request,
                                              controller::FeatureHost& host) {
  controller::Outcome o;
  const std::optional<BreakpointRecord> r = last_written();
  if (request.action == "show") {
    o.accepted = true;
    o.message = (r ? describe(*r) : "the journal holds no record") + "\nwritten " + writer_status();
    return o;
  }
  const bool choice =
      request.action == "resume" || request.action == "retract" || request.action == "discard";
  if (choice) {
    if (!r || !r->valid) {
      o.refusal = control::Refusal::NotApplicable;
      o.message = "the journal holds no valid breakpoint";
      return o;
    }
    if (phase_ == RecoveryPhase::Opening || phase_ == RecoveryPhase::RunningIn ||
        phase_ == RecoveryPhase::Resuming || phase_ == RecoveryPhase::Retracting) {
      o.refusal = control::Refusal::Busy;
      o.message = "a recovery choice is under way";
      return o;
    }
  }
  try {
    if (request.action == "resume") {
      const auto* a = std::any_cast<ResumeArgs>(&request.args);
      if (r->stage != BreakpointStage::AtRest) {
        o.refusal = control::Refusal::NotApplicable;
        o.message =
            "the record was not completed at rest (the power went before the axes stopped): retract or "
            "discard";
        return o;
      }
      return start_resume(*r, a != nullptr ? *a : ResumeArgs{}, host);
    }
    if (request.action == "retract") {
      const auto* a = std::any_cast<RetractArgs>(&request.args);
      if (a == nullptr) throw std::bad_any_cast();
      return start_retract(*r, *a, host);
    }
  } catch (const std::bad_any_cast&) {
    o.refusal = control::Refusal::BadValue;
    o.message = "retract needs RetractArgs";
    return o;
  }
  if (request.action == "discard") {
    recovering_ = *r;
    finish_recovery(true, {});
    o.accepted = true;
    o.message = "breakpoint discarded";
    return o;
  }
  o.refusal = control::Refusal::BadValue;
  o.message = fmt::format("the journal has no action '{}' (show, resume, retract, discard)", request.action);
  return o;
}

}  // namespace opencnc::recovery
