// SPDX-License-Identifier: GPL-3.0-or-later
// Controller: requests → checks → servo commands; programs → preflight → planner → block queue;
// servo events → outcomes and notes.
#include "opencnc/controller/controller.hpp"

#include <fmt/format.h>

#include "opencnc/controller/preflight.hpp"
#include "opencnc/controller/program_tools.hpp"
#include "opencnc/controller/servo_setup.hpp"

namespace opencnc::control {

namespace {

constexpr std::size_t kKeptOutcomes = 4096;

std::string refusal_text(Refusal r) {
  switch (r) {
    case Refusal::None:
      return "";
    case Refusal::EStopActive:
      return "the machine is e-stopped: reset it first";
    case Refusal::EStopInput:
      return "the e-stop chain is still open";
    case Refusal::MachineOff:
      return "the machine is off: turn it on first";
    case Refusal::Faulted:
      return "a fault stopped the machine: reset it first";
    case Refusal::FaultPersists:
      return "the cause of the fault is still there";
    case Refusal::WrongMode:
      return "not possible in this mode";
    case Refusal::Busy:
      return "something is running or held";
    case Refusal::NotHomed:
      return "the machine must be homed first";
    case Refusal::NotApplicable:
      return "nothing to do in this state";
    case Refusal::BadValue:
      return "a value is out of range";
    case Refusal::LimitSwitch:
      return "a limit switch is active";
    case Refusal::NoProgram:
      return "no program is open";
    case Refusal::ProgramError:
      return "the program has errors";
    case Refusal::SoftLimit:
      return "the program would cross a soft limit";
    case Refusal::StartMismatch:
      return "the motion does not start where the machine is";
    case Refusal::Interlock:
      return "an interlock rule of the machine forbids it now";
    case Refusal::HandAxis:
      return "the axis is moved by hand (or is not where the program needs it)";
  }
  return "refused";
}

/// The refusal the servo would give for a run in `state`.
Refusal not_idle(State s) {
  switch (s) {
    case State::EStopped:
      return Refusal::EStopActive;
    case State::Off:
      return Refusal::MachineOff;
    case State::Faulted:
      return Refusal::Faulted;
    default:
      return Refusal::Busy;
  }
}

bool has_code(const Diagnostics& d, const char* code) {
  for (const Diagnostic& x : d.items()) {
    if (x.code == code) return true;
  }
  return false;
}

}  // namespace

/// A run of the servo: its program, its planner, and how far the controller has fed it.
struct Controller::Run {
  std::uint32_t id = 0;
  Mode mode = Mode::Auto;
  std::uint64_t command_id = 0;
  std::shared_ptr<const canon::Program> program;
  canon::SegmentId segment_offset = 0;  ///< run segment k = open program segment offset + k
  std::unique_ptr<plan::Planner> planner;
  bool pumping = true;
  bool pumped_once = false;       ///< the first pump of a run fills the queue, whatever is free
  std::uint32_t next_action = 0;  ///< next program action to consider for a MachineAction record
  canon::SegmentId program_tripped_segment = 0;  ///< the probe move that tripped
};

Controller::Controller(const config::MachineProfile& profile, ServoChannels& channels,
                       std::shared_ptr<ProgramSource> source)
    : profile_(profile),
      servo_config_(control::servo_config(profile)),
      limits_(machine_limits(profile)),
      planner_config_(control::planner_config(profile)),
      channels_(&channels),
      source_(std::move(source)) {}

Controller::~Controller() = default;

std::uint64_t Controller::submit(Request r) {
  std::lock_guard lock(inbox_mutex_);
  const std::uint64_t id = next_id_++;
  inbox_.emplace_back(id, std::move(r));
  inbox_filled_.store(true, std::memory_order_release);
  return id;
}

std::optional<Outcome> Controller::outcome(std::uint64_t id) const {
  std::lock_guard lock(out_mutex_);
  auto it = outcomes_.find(id);
  if (it == outcomes_.end()) return std::nullopt;
  return it->second;
}

ControllerStatus Controller::status() const {
  std::lock_guard lock(out_mutex_);
  ControllerStatus s = published_;
  s.servo = channels_->status.front();  // stable until the next update(), which takes the lock
  return s;
}

std::vector<Note> Controller::take_notes() {
  std::lock_guard lock(out_mutex_);
  std::vector<Note> out;
  out.swap(notes_);
  return out;
}

std::shared_ptr<const canon::Program> Controller::open_program() const {
  std::lock_guard lock(out_mutex_);
  return program_;
}

// --- the periodic work -----------------------------------------------------------------------

void Controller::service() {
  read_servo();
  if (inbox_filled_.load(std::memory_order_acquire)) {
    {
      std::lock_guard lock(inbox_mutex_);
      requests_.swap(inbox_);
      inbox_filled_.store(false, std::memory_order_relaxed);
    }
    for (auto& [id, r] : requests_) handle(id, r);
    requests_.clear();
  }
  pump();

  std::lock_guard lock(out_mutex_);
  ControllerStatus& p = published_;
  p.program_name = program_name_;
  p.program_moves = program_ ? program_->size() : 0;
  p.run_active = run_ != nullptr;
  const bool auto_run = run_ && run_->mode == Mode::Auto;
  p.run_segment = auto_run ? run_->segment_offset + servo().segment : 0;
  p.progress = auto_run && p.program_moves > 0
                   ? std::min(1.0, static_cast<double>(p.run_segment) / static_cast<double>(p.program_moves))
                   : 0.0;
  if (servo().fault.tick != described_fault_tick_ || servo().fault.kind == FaultKind::None) {
    p.fault_text = servo().fault.kind == FaultKind::None ? std::string() : describe(servo().fault);
    described_fault_tick_ = servo().fault.tick;
  }
  p.runs_finished = runs_finished_;
}

void Controller::read_servo() {
  {
    std::lock_guard lock(out_mutex_);  // status() copies the front slot under it
    channels_->status.update();
  }
  ServoEvent e;
  while (channels_->events.try_pop(e)) on_event(e);
}

void Controller::on_event(const ServoEvent& e) {
  switch (e.kind) {
    case EventKind::Accepted:
    case EventKind::Refused:
      if (e.command == CommandKind::StartRun && run_ && e.command_id == run_->command_id &&
          e.kind == EventKind::Refused) {
        run_.reset();
      }
      finish(e.command_id, e.refusal);
      break;
    case EventKind::RunEnded:
      if (!run_ || e.run_id != run_->id) break;
      if (e.run_end == RunEnd::Finished) ++runs_finished_;
      if (e.run_end == RunEnd::ProbeTripped) {
        continue_after_probe();
      } else {
        run_.reset();
      }
      break;
    case EventKind::Fault:
      note(Severity::Error, fault_code(e.fault.kind), describe(e.fault));
      break;
    case EventKind::Message:
      if (run_ && e.run_id == run_->id && e.action < run_->program->actions().size())
        note(Severity::Note, "", run_->program->text(run_->program->actions()[e.action].text));
      break;
    case EventKind::ProbeTripped:
      if (run_ && e.run_id == run_->id) run_->program_tripped_segment = e.segment;
      break;
    case EventKind::Interlock:
    case EventKind::HandAxisMoved:
      note(Severity::Warning, e.kind == EventKind::Interlock ? "control.interlock" : "control.hand-axis",
           interlock_text(e));
      break;
    case EventKind::InputRead:
    case EventKind::StateChanged:
    case EventKind::Homed:
      break;
  }
}

// --- requests --------------------------------------------------------------------------------

void Controller::handle(std::uint64_t id, Request& r) {
  switch (r.kind) {
    case CommandKind::OpenProgram:
      open(id, r);
      return;
    case CommandKind::Mdi:
      mdi(id, r);
      return;
    case CommandKind::SetBlockDelete:
      block_delete_ = r.flag;
      finish(id, Refusal::None);
      return;
    case CommandKind::CycleStart:
      cycle_start(id, r);
      return;
    case CommandKind::StartRun:
      finish(id, Refusal::BadValue, "start-run is the controller's own command");
      return;
    case CommandKind::Abort:
      if (run_) run_->pumping = false;  // no more blocks: the servo drops what it has
      forward(id, r);
      return;
    default:
      forward(id, r);
  }
}

void Controller::forward(std::uint64_t id, const Request& r, const Command& extra) {
  Command c = extra;
  c.id = id;
  c.kind = r.kind;
  c.mode = r.mode;
  c.axis = static_cast<std::int8_t>(r.axis);
  c.flag = r.flag;
  c.value = r.value;
  c.value2 = r.value2;
  if (!channels_->commands.try_push(c)) finish(id, Refusal::Busy, "the servo's command queue is full");
}

std::unique_ptr<plan::Planner> Controller::prepare(const canon::Program& program, Diagnostics& diags) const {
  if (!check_soft_limits(program, servo_config_, diags)) return nullptr;
  auto planner = std::make_unique<plan::Planner>(limits_, planner_config_);
  if (!planner->start(program)) {
    for (const Diagnostic& d : planner->diagnostics().items()) diags.add(d);
    return nullptr;
  }
  return planner;
}

void Controller::open(std::uint64_t id, Request& r) {
  if (run_) return finish(id, Refusal::Busy, "a program is running");
  if (servo().mode != Mode::Auto) return finish(id, Refusal::WrongMode, "programs are opened in Auto mode");
  LoadedProgram lp;
  if (r.program) {
    lp.program = r.program;
  } else if (!source_) {
    return finish(id, Refusal::ProgramError, "this controller has no G-code interpreter");
  } else {
    lp = source_->load(r.text, servo().commanded, {block_delete_});
  }
  if (!lp.program)
    return finish(id, Refusal::ProgramError, "the program has errors", std::move(lp.diagnostics));
  Diagnostics& d = lp.diagnostics;
  auto planner = prepare(*lp.program, d);
  if (!planner) {
    const Refusal why = has_code(d, "control.soft-limit") ? Refusal::SoftLimit : Refusal::ProgramError;
    return finish(id, why, refusal_text(why), std::move(d));
  }
  {
    std::lock_guard lock(out_mutex_);
    program_ = lp.program;
  }
  prepared_ = std::move(planner);  // the first run from here uses it
  prepared_program_ = lp.program;
  program_name_ = r.text;
  program_path_ = r.program ? std::string() : r.text;
  program_block_delete_ = block_delete_;
  finish(id, Refusal::None, {}, std::move(d));
}

void Controller::mdi(std::uint64_t id, const Request& r) {
  if (run_) return finish(id, Refusal::Busy, "something is running");
  if (servo().mode != Mode::Mdi) return finish(id, Refusal::WrongMode, "MDI lines need MDI mode");
  if (servo().state != State::Idle)
    return finish(id, not_idle(servo().state), refusal_text(not_idle(servo().state)));
  if (!source_) return finish(id, Refusal::ProgramError, "this controller has no G-code interpreter");
  LoadedProgram lp = source_->mdi(r.text, servo().commanded);
  if (!lp.program) return finish(id, Refusal::ProgramError, "the line has errors", std::move(lp.diagnostics));
  start_run(id, lp.program, Mode::Mdi, 0);
}

void Controller::cycle_start(std::uint64_t id, const Request& r) {
  if (run_ || servo().mode != Mode::Auto) return forward(id, r);  // the servo continues or says no
  if (!program_) return finish(id, Refusal::NoProgram, refusal_text(Refusal::NoProgram));
  if (servo().state != State::Idle)
    return finish(id, not_idle(servo().state), refusal_text(not_idle(servo().state)));
  std::shared_ptr<const canon::Program> program = program_;
  const bool moved = program->start() != servo().commanded;
  if (!program_path_.empty() && source_ && (moved || program_block_delete_ != block_delete_)) {
    LoadedProgram lp = source_->load(program_path_, servo().commanded, {block_delete_});
    if (!lp.program)
      return finish(id, Refusal::ProgramError, "the program has errors", std::move(lp.diagnostics));
    program = lp.program;
  } else if (moved) {
    program = program_tail(*program, 0, servo().commanded);
  }
  start_run(id, program, Mode::Auto, 0);
}

void Controller::start_run(std::uint64_t id, std::shared_ptr<const canon::Program> program, Mode mode,
                           canon::SegmentId segment_offset) {
  if (servo_config_.homing_required && !servo().all_homed)
    return finish(id, Refusal::NotHomed, refusal_text(Refusal::NotHomed));
  Diagnostics d;
  std::unique_ptr<plan::Planner> planner;
  if (program == prepared_program_ && prepared_) {
    planner = std::move(prepared_);
  } else {
    planner = prepare(*program, d);
  }
  prepared_program_.reset();
  if (!planner) {
    const Refusal why = has_code(d, "control.soft-limit") ? Refusal::SoftLimit : Refusal::ProgramError;
    return finish(id, why, refusal_text(why), std::move(d));
  }
  auto run = std::make_unique<Run>();
  run->id = ++run_counter_;
  run->mode = mode;
  run->command_id = id;
  run->program = std::move(program);
  run->segment_offset = segment_offset;
  run->planner = std::move(planner);
  Command c;
  c.run_id = run->id;
  c.run_mode = mode;
  c.first_block = channels_->blocks.pushed();
  c.first_action = channels_->actions.pushed();
  run_ = std::move(run);
  pump();  // blocks first, so that the servo finds them when it starts
  forward(id, Request::simple(CommandKind::StartRun), c);
}

// The servo stopped after a probe trip, inside the probe move. The rest of the program runs from
// where the machine stands (the moves were interpreted up front, so the probe result does not
// change them; see docs/controller.md).
void Controller::continue_after_probe() {
  const std::unique_ptr<Run> done = std::move(run_);
  const canon::SegmentId next = done->program_tripped_segment + 1;
  if (next >= done->program->size()) return;
  std::uint64_t id;
  {
    std::lock_guard lock(inbox_mutex_);
    id = next_id_++;
  }
  start_run(id, program_tail(*done->program, next, servo().commanded), done->mode,
            done->segment_offset + next);
}

// --- feeding the servo -----------------------------------------------------------------------

// The planner refills the queue in batches, once a quarter of it is free (thousands of blocks,
// seconds of motion, are still queued then): planning many blocks in a row keeps its code and
// data in the cache, where a block or two every period did not.
void Controller::pump() {
  if (!run_ || !run_->pumping) return;
  const canon::Program& p = *run_->program;
  while (run_->next_action < p.actions().size()) {
    const auto a = machine_action(p, run_->next_action);
    if (a && !channels_->actions.try_push(*a)) break;
    ++run_->next_action;
  }
  constexpr std::size_t kRefillSlots = traj::BlockQueue::kCapacity / 4;
  if (run_->pumped_once && channels_->blocks.free_slots() < kRefillSlots) return;
  run_->pumped_once = true;
  switch (run_->planner->pump(channels_->blocks)) {
    case plan::PlanStatus::Working:
      break;
    case plan::PlanStatus::Finished:
      run_->pumping = false;
      break;
    case plan::PlanStatus::Failed: {
      run_->pumping = false;
      for (const Diagnostic& d : run_->planner->diagnostics().items())
        note(Severity::Error, d.code, d.format());
      std::uint64_t id;
      {
        std::lock_guard lock(inbox_mutex_);
        id = next_id_++;
      }
      forward(id, Request::simple(CommandKind::Abort));
      break;
    }
  }
}

// --- answers ---------------------------------------------------------------------------------

void Controller::finish(std::uint64_t id, Refusal refusal, std::string message, Diagnostics diags) {
  std::lock_guard lock(out_mutex_);
  Outcome& o = outcomes_[id];
  o.accepted = refusal == Refusal::None;
  o.refusal = refusal;
  o.message = message.empty() ? refusal_text(refusal) : std::move(message);
  o.diagnostics = std::move(diags);
  while (outcomes_.size() > kKeptOutcomes) outcomes_.erase(outcomes_.begin());
}

void Controller::note(Severity s, std::string code, std::string text) {
  std::lock_guard lock(out_mutex_);
  notes_.push_back(Note{servo().tick, s, std::move(code), std::move(text)});
}

std::string Controller::interlock_text(const ServoEvent& e) const {
  if (e.kind == EventKind::HandAxisMoved) {
    const char axis = e.axis >= 0 && e.axis < kAxisCount ? kAxisLetters[static_cast<std::size_t>(e.axis)] : '?';
    return fmt::format("{} left the position the program needs ({:.4f} mm) while the table moved: feed hold", axis,
                       e.value);
  }
  const auto& texts = profile_.interlocks.rule_texts;
  const std::string rule = e.action < texts.size() ? texts[e.action] : std::string("?");
  const char* what = e.command == CommandKind::SpindleOff ? "stopped the spindle"
                     : e.command == CommandKind::Coolant  ? "stopped the coolant"
                     : e.command == CommandKind::FeedHold ? "held the motion"
                     : e.command == CommandKind::JogStop  ? "stopped the jog"
                                                          : "e-stopped the machine";
  return fmt::format("interlock \"{}\" {}", rule, what);
}

std::string Controller::describe(const Fault& f) const {
  const char axis = f.axis >= 0 && f.axis < kAxisCount ? kAxisLetters[static_cast<std::size_t>(f.axis)] : '?';
  const JointConfig* jc = nullptr;
  for (int j = 0; j < servo_config_.joint_count; ++j) {
    if (servo_config_.joints[static_cast<std::size_t>(j)].axis == f.axis)
      jc = &servo_config_.joints[static_cast<std::size_t>(j)];
  }
  const char* unit = jc != nullptr && jc->rotary ? "deg" : "mm";
  switch (f.kind) {
    case FaultKind::None:
      return "";
    case FaultKind::LimitSwitch:
      return fmt::format("limit switch on {} tripped at {:.4f} {}", axis, f.value, unit);
    case FaultKind::AmpFault:
      return fmt::format("the {} drive reports a fault (at {:.4f} {})", axis, f.value, unit);
    case FaultKind::FollowingError:
      return fmt::format("following error on {}: {:.4f} {}, more than the {} {} allowed", axis, f.value, unit,
                         f.limit, unit);
    case FaultKind::SoftLimit:
      return fmt::format("{} was commanded to {:.4f} {}, beyond its soft limit of {} {}", axis, f.value, unit,
                         f.limit, unit);
    case FaultKind::PowerLoss:
      return fmt::format(
          "power failure: mains lost or running on the UPS (DC link {:.0f} V); the motion was "
          "stopped on the path",
          f.value);
    case FaultKind::Homing:
      return fmt::format("homing {} failed at {:.4f} {}: a limit switch, or the home sensor not on the "
                         "deceleration dog",
                         axis, f.value, unit);
    case FaultKind::Stall:
      return fmt::format("the {} stepper stalled at {:.4f} {}: steps were lost, home it again", axis, f.value,
                         unit);
  }
  return "fault";
}

}  // namespace opencnc::control
