// SPDX-License-Identifier: GPL-3.0-or-later
// RunFromLine: the line to its first move (a quiet scan), the approach, the resume at its segment.
#include "opencnc/run_from_line/run_from_line.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/controller_status.hpp"
#include "opencnc/controller/gcode_source.hpp"

namespace opencnc::run_from_line {

namespace {

constexpr std::size_t kScanBatch = 4096;
constexpr double kPi = 3.14159265358979323846;

/// What the program has set before a move, from its actions: the tool, its length offset, the
/// spindle (0) and the coolant.
struct MachineState {
  int selected = 0;  ///< the last T word
  int tool = -1, tool_index = 0;
  Pose tool_offset{};
  double speed = 0;  ///< rpm, or under G96 the surface speed in mm/min
  bool css = false;
  double css_max_rpm = 0;
  double css_axis_x = 0;  ///< machine X where program X = 0 lies (the spindle's axis)
  int direction = -2, flood = -1, mist = -1;
};

void apply(const canon::Program& p, const canon::Action& a, MachineState& m) {
  using canon::ActionKind;
  if (a.index != 0 && (a.kind == ActionKind::SpindleSpeed || a.kind == ActionKind::SpindleCw ||
                       a.kind == ActionKind::SpindleCcw || a.kind == ActionKind::SpindleStop ||
                       a.kind == ActionKind::SpindleMode))
    return;  // a second spindle: the approach starts only the first
  switch (a.kind) {
    case ActionKind::SelectTool:
      m.selected = a.index;
      break;
    case ActionKind::ChangeTool:
      m.tool = m.selected;
      m.tool_index = a.index;
      break;
    case ActionKind::ChangeToolNumber:
      m.tool = a.index;
      m.tool_index = a.index;
      break;
    case ActionKind::ToolLengthOffset:
      m.tool_offset = p.action_pose(a.pose);
      break;
    case ActionKind::SpindleSpeed:
      m.speed = a.value;
      m.css = a.index2 != 0;
      if (m.css) m.css_axis_x = p.action_pose(a.pose)[Axis::X];
      break;
    case ActionKind::SpindleMode:
      m.css_max_rpm = a.value;
      break;
    case ActionKind::SpindleCw:
      m.direction = 1;
      break;
    case ActionKind::SpindleCcw:
      m.direction = -1;
      break;
    case ActionKind::SpindleStop:
      m.direction = 0;
      break;
    case ActionKind::FloodOn:
      m.flood = 1;
      break;
    case ActionKind::FloodOff:
      m.flood = 0;
      break;
    case ActionKind::MistOn:
      m.mist = 1;
      break;
    case ActionKind::MistOff:
      m.mist = 0;
      break;
    default:
      break;
  }
}

/// Follows the program's actions from `*next` up to those before move `limit`.
void follow(const canon::Program& p, std::size_t limit, std::size_t* next, MachineState* m) {
  for (; *next < p.action_count() && p.action(*next).before_move <= limit; ++*next)
    apply(p, p.action(*next), *m);
}

/// The spindle's rpm at `start`: the speed, or under G96 the surface speed at the radius from
/// the spindle's axis, at most the G96 D limit (0: none known).
double rpm_at(const MachineState& m, const Pose& start) {
  if (!m.css) return m.speed;
  const double r = std::abs(start[Axis::X] - m.css_axis_x);
  const double rpm = r > 0 ? m.speed / (2 * kPi * r) : m.css_max_rpm;
  return m.css_max_rpm > 0 ? std::min(rpm, m.css_max_rpm) : rpm;
}

/// The move's feed in mm/min for the approach's last leg: as the program has it (G94, and G93,
/// whose inverse time the interpreter has already turned into the move's feed per minute); under
/// G95 (F per revolution) × the spindle speed in rpm set before it (0 when unknown: none, or G96).
double feed_per_minute(const canon::Program& p, std::size_t move, const MachineState& m) {
  const double f = p.feed(static_cast<canon::SegmentId>(move));
  if (!(p.move(move).flags & canon::kPerRevolution)) return f;
  return m.css ? 0 : f * m.speed;
}

LineStart line_start(const canon::Program& p, std::size_t move, const controller::ProgramStream& s,
                     const MachineState& m) {
  LineStart l;
  l.segment = p.segment_of(move);
  l.start = p.start_of(static_cast<canon::SegmentId>(move));
  l.rapid = p.move(move).kind == canon::MoveKind::Traverse;
  l.feed_mm_per_min = l.rapid ? 0 : feed_per_minute(p, move, m);
  l.where = s.location_of(move);
  l.tool = m.tool;
  l.tool_index = m.tool_index;
  l.tool_offset = m.tool_offset;
  l.spindle_direction = m.direction;
  l.spindle_rpm = rpm_at(m, l.start);
  l.flood = m.flood;
  l.mist = m.mist;
  return l;
}

}  // namespace

std::optional<LineStart> find_line_start(controller::ProgramSource& source, const std::string& path,
                                         const Pose& program_start, std::uint32_t line,
                                         const controller::LoadOptions& options, std::string* why,
                                         const std::atomic<bool>* cancel) {
  std::unique_ptr<controller::ProgramStream> s = source.execute(path, program_start, options);
  std::uint32_t last_line = 0;  // the main file's line of the last move seen
  std::size_t scanned = 0, next_action = 0;
  MachineState state;  // what the program has set before the move scanned
  for (;;) {
    if (cancel && cancel->load(std::memory_order_relaxed)) {
      *why = "the scan was stopped";
      return std::nullopt;
    }
    const canon::Program& p = s->program();
    for (; scanned < p.size(); ++scanned) {
      if (p.file_of(static_cast<canon::SegmentId>(scanned)) != 0) continue;
      const std::uint32_t at = p.move(scanned).line;
      if (at == line) {
        follow(p, scanned, &next_action, &state);
        const LineStart l = line_start(p, scanned, *s, state);
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
    follow(p, scanned, &next_action, &state);
    // What is passed is freed (the last move stays: the next one starts at its end).
    if (scanned > 1) s->release(scanned - 1, p.action_count());
    switch (s->state()) {
      case controller::StreamState::Reading:
        s->read(kScanBatch);
        break;
      case controller::StreamState::Sync: {
        const controller::SyncRequest& r = s->sync_request();
        if (r.kind == controller::SyncKind::Probe || r.kind == controller::SyncKind::Input) {
          *why = fmt::format(
              "line {} comes after the {} at {}: its answer is not known again, so the program "
              "cannot be replayed past it (run from a line before it)",
              line, to_string(r.kind), to_string(r.where));
          return std::nullopt;
        }
        controller::SyncAnswer a;  // a stop or a tool change: the program goes on from there
        a.kind = r.kind;
        a.position = p.empty() ? program_start : p.end(static_cast<canon::SegmentId>(p.size() - 1));
        s->answer(a);
        break;
      }
      case controller::StreamState::Finished:
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
      case controller::StreamState::Error:
        *why = s->diagnostics().items().empty() ? std::string("the program failed")
                                                : s->diagnostics().items().front().format();
        return std::nullopt;
    }
  }
}

std::shared_ptr<const tools::ToolTable> ScanToolTable::snapshot() const {
  std::lock_guard lock(mutex_);
  return own_ ? own_->snapshot() : live_->snapshot();
}

std::uint64_t ScanToolTable::version() const {
  std::lock_guard lock(mutex_);
  return live_->version() + changes_;
}

bool ScanToolTable::update(std::size_t index, const tools::ToolEntry& entry, tools::ChangeSource source,
                           Diagnostics& diags) {
  std::lock_guard lock(mutex_);
  if (!own_) own_ = std::make_unique<tools::MemoryToolTable>(*live_->snapshot());
  ++changes_;
  return own_->update(index, entry, source, diags);
}

void ScanToolTable::reset() {
  std::lock_guard lock(mutex_);
  if (!own_) return;
  own_.reset();
  ++changes_;
}

RunFromLineFeature::~RunFromLineFeature() {
  if (scan_) {
    scan_->cancel = true;
    scan_->thread.join();
  }
}

controller::Outcome RunFromLineFeature::handle(const controller::requests::Feature& request,
                                               controller::FeatureHost& host) {
  controller::Outcome o;
  o.refusal = control::Refusal::BadValue;
  if (request.action != "start") {
    o.message = fmt::format("run-from-line has no action '{}' (start)", request.action);
    return o;
  }
  const auto* args = std::any_cast<RunFromLineArgs>(&request.args);
  if (args == nullptr || args->line == 0) {
    o.message = "run-from-line start needs a line (1 or more)";
    return o;
  }
  const controller::ControllerStatus& s = host.current_status();
  if (s.program_name.empty()) {
    o.refusal = control::Refusal::NoProgram;
    o.message = "no program is open";
    return o;
  }
  if (s.run_active || pending_ || scan_) {
    o.refusal = control::Refusal::Busy;
    o.message = scan_ ? fmt::format("run from line {}: the scan of the program is under way", scan_->line)
                      : "a program is running";
    return o;
  }
  if (s.servo.mode != control::Mode::Auto) {
    o.refusal = control::Refusal::WrongMode;
    o.message = "run from line needs auto mode";
    return o;
  }
  if (s.servo.state != control::State::Idle) {
    o.refusal = control::Refusal::Busy;
    o.message = fmt::format("the machine is {}, not idle", to_string(s.servo.state));
    return o;
  }
  // The scan replays the interpreter over the file up to the line: a long program must not
  // hold the controller, so it runs on a thread of its own and the answer waits for it.
  // The scan's interpreter selects from the conditions an admin may have added or deleted since.
  source_->profile_changed(host.profile());
  scan_ = std::make_unique<Scan>();
  Scan& scan = *scan_;
  scan.request = host.defer();
  scan.line = args->line;
  scan.opened = opened_;
  scan.thread = std::thread([&scan, source = source_, tools = tools_, path = s.program_name,
                             from = program_start_, options = controller::LoadOptions{s.block_delete}] {
    try {
      if (tools) tools->reset();
      scan.at = find_line_start(*source, path, from, scan.line, options, &scan.why, &scan.cancel);
    } catch (const std::exception& ex) {
      scan.at.reset();
      scan.why = fmt::format("the scan failed: {}", ex.what());
    }
    scan.done.store(true, std::memory_order_release);
  });
  return o;
}

void RunFromLineFeature::poll(controller::FeatureHost& host) {
  if (!scan_ || !scan_->done.load(std::memory_order_acquire)) return;
  scan_->thread.join();
  const std::unique_ptr<Scan> scan = std::move(scan_);
  controller::Outcome o;
  o.refusal = control::Refusal::BadValue;
  const controller::ControllerStatus& s = host.current_status();
  if (!scan->at) {
    o.message = scan->why;
  } else if (scan->opened != opened_) {
    o.refusal = control::Refusal::NoProgram;
    o.message = fmt::format("run from line {}: another program was opened during the scan", scan->line);
  } else if (s.servo.mode != control::Mode::Auto || s.servo.state != control::State::Idle || s.run_active) {
    o.refusal = s.servo.mode != control::Mode::Auto ? control::Refusal::WrongMode : control::Refusal::Busy;
    o.message = fmt::format("run from line {}: the machine left auto mode or idle during the scan ({}, {})",
                            scan->line, to_string(s.servo.mode), to_string(s.servo.state));
  } else {
    start_approach(*scan, host);
    o.accepted = true;
    o.refusal = control::Refusal::None;
    o.message = fmt::format("from line {} (segment {}, {}): the approach{}, then the program", scan->line,
                            scan->at->segment, to_string(scan->at->where),
                            scan->at->tool >= 0 && scan->at->tool != s.servo.tool
                                ? fmt::format(" with tool {} changed in", scan->at->tool)
                                : std::string());
  }
  host.answer(scan->request, std::move(o));
}

// While the scan runs the machine stays idle: nothing else may start.
bool RunFromLineFeature::allow_start(const controller::StartCheck& /*start*/,
                                     controller::FeatureHost& /*host*/, std::string* why) {
  if (!scan_) return true;
  *why = fmt::format("run from line {}: the scan of the program is under way", scan_->line);
  return false;
}

void RunFromLineFeature::start_approach(Scan& scan, controller::FeatureHost& host) {
  const controller::ControllerStatus& s = host.current_status();
  pending_ = scan.at;
  pending_line_ = scan.line;
  approach_request_ = host.submit(controller::Request::run_auxiliary(
      fmt::format("approach to line {}", scan.line), approach(s.servo.commanded, s.servo.tool, *scan.at)));
}

namespace {

/// Rapids to the profile's tool-change position as the interpreter's M6 does (Z alone first when
/// asked); returns where the machine then stands. The builder has no offsets yet: its points are
/// machine coordinates.
Pose to_tool_change(canon::ProgramBuilder& b, canon::SegmentId& id, const Pose& from,
                    const config::ToolChangeProfile& tc) {
  Pose there = from;
  for (int i = 0; i < kAxisCount; ++i) {
    if (tc.axes.has(static_cast<Axis>(i))) there[i] = tc.position[i];
  }
  if (there == from) return from;
  if (tc.z_first && there[Axis::Z] != from[Axis::Z]) {
    Pose up = from;
    up[Axis::Z] = there[Axis::Z];
    if (!(up == there)) b.straight_traverse(id++, up);
  }
  b.straight_traverse(id++, there);
  return there;
}

}  // namespace

// The line's tool changed in first (M6 through the machine's own path: the spindle stopped, the
// profile's tool-change position, the changer or the operator's dialog), then the spindle and the
// coolant as the program has them at the line, then up to the higher of the two Z, across, and
// down onto the move's start: at the move's own feed when it is a feed move (the tool may be near
// the work there), else at rapid. The points carry the line's tool-length offset, so the status
// shows the work position the program will have.
std::shared_ptr<const canon::Program> RunFromLineFeature::approach(const Pose& machine, int spindle_tool,
                                                                   const LineStart& to) const {
  canon::ProgramBuilder b(host_->profile().axis_mask(), machine);
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);  // each leg ends where it is programmed
  Pose from = machine;
  canon::SegmentId id = 0;
  if (to.tool >= 0 && to.tool != spindle_tool) {
    b.select_tool(to.tool);
    const config::InterpreterOptions& i = host_->profile().interpreter;
    // As the interpreter's M6: a Fanuc lathe's turret indexes with the spindle turning.
    if (!(i.dialect == config::Dialect::Fanuc && i.machine == config::MachineKind::Lathe))
      b.stop_spindle_turning(0);
    from = to_tool_change(b, id, from, host_->profile().tool_change);
    b.change_tool(to.tool_index);
  }
  b.use_tool_length_offset(to.tool_offset);
  if (to.spindle_direction != -2) {
    if (to.spindle_rpm > 0) b.set_spindle_speed(0, to.spindle_rpm);
    if (to.spindle_direction == 1) b.start_spindle_clockwise(0);
    if (to.spindle_direction == -1) b.start_spindle_counterclockwise(0);
    if (to.spindle_direction == 0) b.stop_spindle_turning(0);
  }
  if (to.flood == 1) b.flood_on();
  if (to.flood == 0) b.flood_off();
  if (to.mist == 1) b.mist_on();
  if (to.mist == 0) b.mist_off();
  const auto program_point = [&](Pose p) {  // machine → the builder's (offset by the tool length)
    for (int i = 0; i < kAxisCount; ++i) p[i] -= to.tool_offset[i];
    return p;
  };
  Pose up = from;
  up[Axis::Z] = std::max(from[Axis::Z], to.start[Axis::Z]);
  if (up[Axis::Z] != from[Axis::Z]) b.straight_traverse(id++, program_point(up));
  Pose across = to.start;
  across[Axis::Z] = up[Axis::Z];
  if (!(across == up)) b.straight_traverse(id++, program_point(across));
  if (across[Axis::Z] != to.start[Axis::Z]) {
    if (to.rapid || to.feed_mm_per_min <= 0) {
      b.straight_traverse(id++, program_point(to.start));
    } else {
      b.set_feed_rate(to.feed_mm_per_min);
      b.straight_feed(id++, program_point(to.start));
    }
  }
  b.program_end();
  return std::make_shared<const canon::Program>(b.take());
}

void RunFromLineFeature::on_event(const controller::ControllerEvent& e) {
  if (!host_) return;
  // Where the program starts from, as the controller's own resume takes it: where the machine
  // stood when the program was opened or last started by the operator.
  const bool started =
      e.kind == controller::ControllerEventKind::JobStarted && e.job == controller::JobKind::Program;
  if (e.kind == controller::ControllerEventKind::ProgramOpened) ++opened_;
  if (e.kind == controller::ControllerEventKind::ProgramOpened || (started && !resuming_)) {
    program_start_ = host_->current_status().servo.commanded;
  }
  if (started) resuming_ = false;
  if (!pending_) return;
  if (e.kind == controller::ControllerEventKind::Answer && e.request_id == approach_request_ && !e.accepted) {
    pending_.reset();
    host_->note(Severity::Warning, "control.run-from-line",
                fmt::format("run from line {}: the approach was refused: {}", pending_line_, e.text));
    return;
  }
  const std::string name = fmt::format("approach to line {}", pending_line_);
  if (e.kind == controller::ControllerEventKind::JobEnded && e.job == controller::JobKind::Auxiliary &&
      e.text.starts_with(name)) {
    const LineStart at = *pending_;
    pending_.reset();
    if (e.end != controller::JobEnd::Finished) {
      host_->note(
          Severity::Warning, "control.run-from-line",
          fmt::format("run from line {}: the approach did not finish ({}); the program was not started",
                      pending_line_, to_string(e.end)));
      return;
    }
    resuming_ = true;
    host_->submit(controller::Request::resume(at.segment, program_start_));
  }
}

}  // namespace opencnc::run_from_line
