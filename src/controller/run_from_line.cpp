// SPDX-License-Identifier: GPL-3.0-or-later
// RunFromLine: the line to its first move (a quiet scan), the approach, the resume at its segment.
#include "opencnc/controller/run_from_line.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/controller_status.hpp"

namespace opencnc::control {

namespace {

constexpr std::size_t kScanBatch = 4096;

/// The spindle speed (rpm) the program has set before move `limit`, reading its actions from
/// `*next` on (0: none, or a surface speed under G96, whose rpm depends on X).
void follow_spindle(const canon::Program& p, std::size_t limit, std::size_t* next, double* rpm) {
  for (; *next < p.action_count() && p.action(*next).before_move <= limit; ++*next) {
    const canon::Action& a = p.action(*next);
    if (a.kind == canon::ActionKind::SpindleSpeed) *rpm = a.index2 == 0 ? a.value : 0;
  }
}

/// The move's feed in mm/min for the approach's last leg: as the program has it (G94, and G93,
/// whose inverse time the interpreter has already turned into the move's feed per minute); under
/// G95 (F per revolution) × the spindle speed set before it (0 when unknown).
double feed_per_minute(const canon::Program& p, std::size_t move, double rpm) {
  const double f = p.feed(static_cast<canon::SegmentId>(move));
  return (p.move(move).flags & canon::kPerRevolution) ? f * rpm : f;
}

LineStart line_start(const canon::Program& p, std::size_t move, const ProgramStream& s, double rpm) {
  LineStart l;
  l.segment = p.segment_of(move);
  l.start = p.start_of(static_cast<canon::SegmentId>(move));
  l.rapid = p.move(move).kind == canon::MoveKind::Traverse;
  l.feed_mm_per_min = l.rapid ? 0 : feed_per_minute(p, move, rpm);
  l.where = s.location_of(move);
  return l;
}

}  // namespace

std::optional<LineStart> find_line_start(ProgramSource& source, const std::string& path,
                                         const Pose& program_start, std::uint32_t line,
                                         const LoadOptions& options, std::string* why) {
  std::unique_ptr<ProgramStream> s = source.execute(path, program_start, options);
  std::uint32_t last_line = 0;  // the main file's line of the last move seen
  std::size_t scanned = 0, next_action = 0;
  double rpm = 0;  // the spindle speed set before the move scanned
  for (;;) {
    const canon::Program& p = s->program();
    for (; scanned < p.size(); ++scanned) {
      if (p.file_of(static_cast<canon::SegmentId>(scanned)) != 0) continue;
      const std::uint32_t at = p.move(scanned).line;
      if (at == line) {
        follow_spindle(p, scanned, &next_action, &rpm);
        const LineStart l = line_start(p, scanned, *s, rpm);
        if (!l.rapid && l.feed_mm_per_min <= 0) {
          *why = fmt::format(
              "line {} feeds per revolution (G95) and no spindle speed in rpm is set before it (none, or "
              "G96's surface speed): the approach's feed is not known; run from an earlier line",
              line);
          return std::nullopt;
        }
        return l;
      }
      last_line = std::max(last_line, at);
    }
    follow_spindle(p, scanned, &next_action, &rpm);
    // What is passed is freed (the last move stays: the next one starts at its end).
    if (scanned > 1) s->release(scanned - 1, p.action_count());
    switch (s->state()) {
      case StreamState::Reading:
        s->read(kScanBatch);
        break;
      case StreamState::Sync: {
        const SyncRequest& r = s->sync_request();
        if (r.kind == SyncKind::Probe || r.kind == SyncKind::Input) {
          *why = fmt::format(
              "line {} comes after the {} at {}: its answer is not known again, so the program "
              "cannot be replayed past it (run from a line before it)",
              line, to_string(r.kind), to_string(r.where));
          return std::nullopt;
        }
        SyncAnswer a;  // a stop or a tool change: the program goes on from there
        a.kind = r.kind;
        a.position = p.empty() ? program_start : p.end(static_cast<canon::SegmentId>(p.size() - 1));
        s->answer(a);
        break;
      }
      case StreamState::Finished:
        if (line > last_line && line >= s->location().line) {
          *why = fmt::format("line {} is past the program's end (line {}; its last move is on line {})", line,
                             s->location().line, last_line);
          return std::nullopt;
        }
        *why = fmt::format(
            "line {} makes no move (a line without motion, or in a subroutine that is not "
            "called): choose the line of a move",
            line);
        return std::nullopt;
      case StreamState::Error:
        *why = s->diagnostics().items().empty() ? std::string("the program failed")
                                                : s->diagnostics().items().front().format();
        return std::nullopt;
    }
  }
}

Outcome RunFromLineFeature::handle(const requests::Feature& request, FeatureHost& host) {
  Outcome o;
  o.refusal = Refusal::BadValue;
  if (request.action != "start") {
    o.message = fmt::format("run-from-line has no action '{}' (start)", request.action);
    return o;
  }
  const auto* args = std::any_cast<RunFromLineArgs>(&request.args);
  if (args == nullptr || args->line == 0) {
    o.message = "run-from-line start needs a line (1 or more)";
    return o;
  }
  const ControllerStatus& s = host.current_status();
  if (s.program_name.empty()) {
    o.refusal = Refusal::NoProgram;
    o.message = "no program is open";
    return o;
  }
  if (s.run_active || pending_) {
    o.refusal = Refusal::Busy;
    o.message = "a program is running";
    return o;
  }
  if (s.servo.mode != Mode::Auto) {
    o.refusal = Refusal::WrongMode;
    o.message = "run from line needs auto mode";
    return o;
  }
  if (s.servo.state != State::Idle) {
    o.refusal = Refusal::Busy;
    o.message = fmt::format("the machine is {}, not idle", to_string(s.servo.state));
    return o;
  }
  std::string why;
  std::optional<LineStart> at =
      find_line_start(*source_, s.program_name, program_start_, args->line, {s.block_delete}, &why);
  if (!at) {
    o.message = why;
    return o;
  }
  pending_ = at;
  pending_line_ = args->line;
  approach_request_ = host.submit(Request::run_auxiliary(fmt::format("approach to line {}", args->line),
                                                         approach(s.servo.commanded, *at)));
  o.accepted = true;
  o.refusal = Refusal::None;
  o.message = fmt::format("from line {} (segment {}, {}): the approach, then the program", args->line,
                          at->segment, to_string(at->where));
  return o;
}

// Up to the higher of the two Z, across, then down onto the move's start: at the move's own feed
// when it is a feed move (the tool may be near the work there), else at rapid.
std::shared_ptr<const canon::Program> RunFromLineFeature::approach(const Pose& from,
                                                                   const LineStart& to) const {
  canon::ProgramBuilder b(host_->profile().axis_mask(), from);
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);  // each leg ends where it is programmed
  Pose up = from;
  up[Axis::Z] = std::max(from[Axis::Z], to.start[Axis::Z]);
  canon::SegmentId id = 0;
  if (up[Axis::Z] != from[Axis::Z]) b.straight_traverse(id++, up);
  Pose across = to.start;
  across[Axis::Z] = up[Axis::Z];
  if (!(across == up)) b.straight_traverse(id++, across);
  if (across[Axis::Z] != to.start[Axis::Z]) {
    if (to.rapid || to.feed_mm_per_min <= 0) {
      b.straight_traverse(id++, to.start);
    } else {
      b.set_feed_rate(to.feed_mm_per_min);
      b.straight_feed(id++, to.start);
    }
  }
  b.program_end();
  return std::make_shared<const canon::Program>(b.take());
}

void RunFromLineFeature::on_event(const ControllerEvent& e) {
  if (!host_) return;
  // Where the program starts from, as the controller's own resume takes it: where the machine
  // stood when the program was opened or last started by the operator.
  const bool started = e.kind == ControllerEventKind::JobStarted && e.job == JobKind::Program;
  if (e.kind == ControllerEventKind::ProgramOpened || (started && !resuming_)) {
    program_start_ = host_->current_status().servo.commanded;
  }
  if (started) resuming_ = false;
  if (!pending_) return;
  if (e.kind == ControllerEventKind::Answer && e.request_id == approach_request_ && !e.accepted) {
    pending_.reset();
    host_->note(Severity::Warning, "control.run-from-line",
                fmt::format("run from line {}: the approach was refused: {}", pending_line_, e.text));
    return;
  }
  const std::string name = fmt::format("approach to line {}", pending_line_);
  if (e.kind == ControllerEventKind::JobEnded && e.job == JobKind::Auxiliary && e.text.starts_with(name)) {
    const LineStart at = *pending_;
    pending_.reset();
    if (e.end != JobEnd::Finished) {
      host_->note(
          Severity::Warning, "control.run-from-line",
          fmt::format("run from line {}: the approach did not finish ({}); the program was not started",
                      pending_line_, to_string(e.end)));
      return;
    }
    resuming_ = true;
    host_->submit(Request::resume(at.segment, program_start_));
  }
}

}  // namespace opencnc::control
