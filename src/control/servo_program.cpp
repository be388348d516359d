// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, Auto and MDI runs: the interpolator's inputs and outputs, the machine side of the
// program's markers (spindle, coolant, outputs, tool change, M66, M19, hand-axis waits), probing,
// run end (and homing again after a part where the profile asks for it).
#include <algorithm>
#include <cmath>

#include "opencnc/control/servo.hpp"

namespace opencnc::control {

namespace {

/// Blocks looked at ahead of the interpolator for a spindle wait (a bounded loop).
constexpr std::uint64_t kMarkerScan = 64;

bool take(bool& edge) noexcept {
  const bool was = edge;
  edge = false;
  return was;
}

}  // namespace

const traj::MotionBlock* Servo::block(std::uint64_t seq) const noexcept {
  const traj::BlockQueue& q = channels_->blocks;
  const std::uint64_t first = q.popped();
  if (seq < first || seq - first >= q.available()) return nullptr;
  return &q.peek(static_cast<std::size_t>(seq - first));
}

// The drive's at-speed signal refers to the command it had when it sampled: only from the period
// after a change on does it speak about the new one. A start an interlock holds back is not at
// speed, whatever the drive says of the standing spindle it was told to keep still.
bool Servo::spindle_at_speed() const noexcept {
  if (!caps_.spindle) return true;
  if (spindle_direction_ == machine::SpindleDirection::Stopped) return true;
  if (!spindle_running_) return false;
  return in_.spindle.at_speed && tick_ > spindle_changed_tick_;
}

// The interpolator reports the markers it passes and may reach a spindle-wait marker in the same
// period; the M3/M4 before that wait is applied only after the period. So while the next
// action record still to be applied is a spindle one and a spindle wait for it (or later) comes
// before any other stop, the spindle is not at speed yet.
bool Servo::spindle_change_pending() const noexcept {
  // A wait is only decided with the motion at rest (it is a stop): while moving, nothing to do.
  if (tick_out_.path_velocity != 0) return false;
  const auto& ring = channels_->actions;
  if (ring.available() == 0) return false;
  const MachineAction& next = ring.front();
  const bool spindle = next.code == ActionCode::SpindleCw || next.code == ActionCode::SpindleCcw ||
                       next.code == ActionCode::SpindleSpeed || next.code == ActionCode::SpindleStop ||
                       next.code == ActionCode::SpindleMode || next.code == ActionCode::SurfaceSpeed;
  if (!spindle) return false;
  const traj::BlockQueue& q = channels_->blocks;
  const std::uint64_t first = std::max(q.popped(), tick_out_.block_seq);
  for (std::uint64_t seq = first, n = 0; n < kMarkerScan && block(seq) != nullptr; ++seq, ++n) {
    const traj::MotionBlock& b = *block(seq);
    if (b.kind != traj::BlockKind::Marker || b.marker == traj::MarkerKind::Report) continue;
    return b.marker == traj::MarkerKind::SpindleWait && b.action >= next.action;
  }
  return false;
}

void Servo::stop_spindle_and_coolant() noexcept {
  spindle_direction_ = machine::SpindleDirection::Stopped;
  orient_ = false;
  flood_ = mist_ = false;
  preparing_ = false;
  sync_step_ = SyncStep::None;
}

traj::TickInput Servo::program_inputs() noexcept {
  traj::TickInput in;
  const bool torch_waits = torch_.head_waits();  // the torch's sequence moves it up or down
  in.feed_override = torch_waits ? 0.0 : feed_override_ * gap_.feed_scale();     // the EDM gap servo's speed
  in.rapid_override = gap_.head_waits() || torch_waits ? 0.0 : rapid_override_;  // rapids wait too
  in.feed_hold = hold_;
  in.cycle_start = take(cycle_start_edge_);
  released_ = in.cycle_start;
  in.abort = take(abort_edge_);
  in.single_block = single_block_;
  in.optional_stop = optional_stop_;
  in.sync_done = take(sync_done_edge_);
  in.spindle_at_speed = spindle_at_speed() && !spindle_change_pending();
  in.spindle_revs = in_.spindle.position_rev;
  in.spindle_rev_s = in_.spindle.speed_rpm / 60.0;
  in.in_position = coupling_in_position();
  if (power_stop_) {
    choose_stop_scale();
    in.abort_decel_scale = stop_scale_;
  }
  return in;
}

void Servo::run_program() noexcept {
  interp_.tick(program_inputs(), tick_out_);
  check_engage_wait();
  if (activity_ != Activity::Program) return;  // it faulted: the run has ended
  for (int j = 0; j < config_.joint_count; ++j) {
    const int axis = config_.joints[static_cast<std::size_t>(j)].axis;
    // The torch's offset stays on its axis until its stage moves it (also in the period a run ends).
    if (!manual(j))
      commanded_[axis] = tick_out_.position[axis] + (axis == torch_axis_ ? torch_.offset_mm() : 0.0);
  }
  apply_reports();
  report_sync_points();
  check_probe();
  check_hand_guard();
  if (tick_out_.state == traj::RunState::WaitingSync) {
    run_sync();
  } else {
    sync_step_ = SyncStep::None;
  }
  map_program_state();
  if (tick_out_.state == traj::RunState::Finished) end_run(RunEnd::Finished);
  if (tick_out_.state == traj::RunState::Aborted) end_run(power_stop_ ? RunEnd::Faulted : RunEnd::Aborted);
}

void Servo::map_program_state() noexcept {
  switch (tick_out_.state) {
    case traj::RunState::Dwelling:
      wait_ = Wait::Dwell;  // status coupling_wait tells a coupling code's wait from a G4
      break;
    case traj::RunState::WaitingSpindle:
      // A start an interlock rule holds back is a wait of its own (status: interlock_rule).
      wait_ =
          spindle_direction_ != machine::SpindleDirection::Stopped && !spindle_running_ && spindle_blocked_
              ? Wait::Interlock
              : Wait::Spindle;
      break;
    case traj::RunState::Starved:
      wait_ = Wait::Starved;
      break;
    case traj::RunState::WaitingSync:
      break;  // run_sync() says what for
    default:
      wait_ = Wait::None;
  }
  if (aborting_) {
    set_state(State::Running);
  } else if (hold_) {
    set_state(State::Held);
  } else if (tick_out_.state == traj::RunState::WaitingCycleStart && !released_) {
    const traj::MotionBlock* b = block(tick_out_.block_seq);
    const traj::MarkerKind k = b != nullptr ? b->marker : traj::MarkerKind::None;
    if (k == traj::MarkerKind::OptionalStop && !optional_stop_) {  // the interpolator lets it pass
      set_state(State::Running);
      return;
    }
    set_state(State::Stopped);
    stop_reason_ = k == traj::MarkerKind::ProgramStop    ? StopReason::ProgramStop
                   : k == traj::MarkerKind::OptionalStop ? StopReason::OptionalStop
                                                         : StopReason::SingleBlock;
  } else {
    set_state(State::Running);
  }
}

// Records are pushed in action order and consumed in that order; one that is older than the
// marker asking is a marker that was passed without one (cannot happen with the planner's
// markers, but a stale record must never block the run).
bool Servo::take_action(std::uint32_t action, MachineAction& out) noexcept {
  if (action == traj::kNoAction) return false;  // a marker of the planner's own (probe end)
  auto& ring = channels_->actions;
  while (ring.available() > 0 && ring.front().action < action) ring.pop();
  if (ring.available() == 0 || ring.front().action != action) return false;
  ring.try_pop(out);
  return true;
}

// Report markers, and the zero-time stops that carry a record (the coupling codes: a dwell
// marker whose record is next in the ring; a G4 has none).
void Servo::apply_reports() noexcept {
  const auto& ring = channels_->actions;
  for (int e = 0; e < tick_out_.event_count; ++e) {
    const traj::TickEvent& ev = tick_out_.events[static_cast<std::size_t>(e)];
    const bool record_stop =
        ev.kind == traj::MarkerKind::Dwell && ring.available() > 0 && ring.front().action == ev.action &&
        (ring.front().code == ActionCode::AxisCoupling || ring.front().code == ActionCode::ProcessCode);
    if (ev.kind != traj::MarkerKind::Report && !record_stop) continue;
    MachineAction a;
    if (take_action(ev.action, a)) apply_action(a);
  }
}

// The controller's interpreter waits at sync points (probe, M66, M6, program stops) until the
// machine is past them: say so when the commanded position moves on from one.
void Servo::report_sync_points() noexcept {
  for (int e = 0; e < tick_out_.event_count; ++e) {
    const traj::TickEvent& ev = tick_out_.events[static_cast<std::size_t>(e)];
    const bool sync_point = ev.kind == traj::MarkerKind::Sync || ev.kind == traj::MarkerKind::ProgramStop ||
                            ev.kind == traj::MarkerKind::OptionalStop;
    if (!sync_point) continue;
    ServoEvent out;
    out.kind = EventKind::SyncPassed;
    out.run_id = run_id_;
    out.action = ev.action;
    out.segment = tick_out_.segment;
    out.value = input_value_;
    emit(out);
  }
}

void Servo::apply_action(const MachineAction& a) noexcept {
  const auto channel_ok = [](int i, int n) { return i >= 0 && i < n; };
  switch (a.code) {
    case ActionCode::SpindleSpeed:
      spindle_rpm_ = a.value;
      spindle_changed_tick_ = tick_;
      break;
    case ActionCode::SpindleMode:
      css_max_rpm_ = a.value;
      spindle_changed_tick_ = tick_;
      break;
    case ActionCode::SurfaceSpeed:
      css_surface_mm_min_ = a.value;
      css_axis_x_ = a.value2;
      spindle_changed_tick_ = tick_;
      break;
    case ActionCode::SpindleCw:
    case ActionCode::SpindleCcw:
      spindle_direction_ = a.code == ActionCode::SpindleCw ? machine::SpindleDirection::Clockwise
                                                           : machine::SpindleDirection::Counterclockwise;
      spindle_changed_tick_ = tick_;
      orient_ = false;
      break;
    case ActionCode::SpindleStop:
      spindle_direction_ = machine::SpindleDirection::Stopped;
      spindle_changed_tick_ = tick_;
      orient_ = false;
      break;
    case ActionCode::SelectTool:
      selected_tool_ = a.index;
      preparing_tool_ = a.index;
      preparing_ = caps_.tool_changer;
      if (!caps_.tool_changer) prepared_tool_ = a.index;
      break;
    case ActionCode::SetToolNumber:
      tool_ = a.index;
      break;
    case ActionCode::FloodOn:
    case ActionCode::FloodOff:
      flood_ = a.code == ActionCode::FloodOn;
      break;
    case ActionCode::MistOn:
    case ActionCode::MistOff:
      mist_ = a.code == ActionCode::MistOn;
      break;
    case ActionCode::SpindleOverrideEnable:
    case ActionCode::SpindleOverrideDisable:
      spindle_override_enabled_ = a.code == ActionCode::SpindleOverrideEnable;
      break;
    case ActionCode::DigitalOutput:
      if (channel_ok(a.index, caps_.digital_outputs)) {
        const std::uint64_t bit = std::uint64_t{1} << a.index;
        digital_out_ = a.index2 != 0 ? (digital_out_ | bit) : (digital_out_ & ~bit);
      }
      break;
    case ActionCode::AnalogOutput:
      if (channel_ok(a.index, caps_.analog_outputs)) analog_out_[static_cast<std::size_t>(a.index)] = a.value;
      break;
    case ActionCode::Message: {
      ServoEvent e;
      e.kind = EventKind::Message;
      e.run_id = run_id_;
      e.action = a.action;
      emit(e);
      break;
    }
    case ActionCode::AxisCoupling:
      engage_coupling(a);
      break;
    case ActionCode::ProcessCode:
      // The torch's codes, else the EDM's (the preflight refuses codes the machine lacks).
      if (!(torch_.enabled() && torch_.apply_code(a.index, a.value)))
        gap_.apply_code(a.index, a.value, a.value2);
      break;
    case ActionCode::ChangeTool:
    case ActionCode::WaitInput:
    case ActionCode::SpindleOrient:
    case ActionCode::PalletShuttle:
    case ActionCode::HandAxisWait:
    case ActionCode::Ignore:
      break;  // handshakes are Sync markers (run_sync); the rest needs nothing from the machine
  }
}

// --- Sync markers: the program waits until the machine has done something -------------------

void Servo::run_sync() noexcept {
  if (sync_done_edge_) return;  // done; the interpolator sees it this tick
  // Released last tick: the interpolator waits at the next marker, which shows from the next tick.
  if (sync_step_ == SyncStep::None && tick_out_.block_seq == sync_seq_) return;
  if (sync_step_ == SyncStep::None) {
    begin_sync();
  } else if (step_sync()) {
    sync_step_ = SyncStep::None;
    sync_done_edge_ = true;
  }
}

void Servo::begin_sync() noexcept {
  // Reports passed in this very tick may still be queued behind a full event list: wait a tick.
  if (tick_out_.event_count == traj::kMaxTickEvents) return;
  const traj::MotionBlock* m = block(tick_out_.block_seq);
  sync_seq_ = tick_out_.block_seq;
  MachineAction a;
  if (m == nullptr || !take_action(m->action, a)) {  // a probe move's end: nothing to do here
    wait_ = Wait::Probe;
    sync_done_edge_ = true;
    return;
  }
  sync_action_ = a;
  sync_started_tick_ = tick_;
  switch (a.code) {
    case ActionCode::ChangeTool:
      sync_step_ = caps_.tool_changer ? SyncStep::ToolChanger : SyncStep::ManualTool;
      wait_ = caps_.tool_changer ? Wait::ToolChanger : Wait::ManualToolChange;
      manual_tool_done_ = false;
      out_.tool.prepare_tool = selected_tool_;
      break;
    case ActionCode::WaitInput: {
      sync_step_ = SyncStep::Input;
      wait_ = Wait::Input;
      sync_input_before_ = (in_.digital_in >> std::clamp(a.index, 0, 63)) & 1u;
      break;
    }
    case ActionCode::SpindleOrient:
      orient_ = true;
      orient_angle_ = a.value;
      sync_step_ = caps_.spindle_orient ? SyncStep::Orient : SyncStep::None;
      wait_ = Wait::Orient;
      if (!caps_.spindle_orient) sync_done_edge_ = true;
      break;
    case ActionCode::HandAxisWait: {
      const int j = joint_of(a.index);
      hand_wait_.axis = static_cast<std::int8_t>(a.index);
      hand_wait_.target = a.value;
      hand_wait_.retract = a.index2 > 0;
      hand_wait_.tolerance = j >= 0 ? config_.joints[static_cast<std::size_t>(j)].hand_tolerance : 0.0;
      hand_guard_ = false;
      sync_step_ = j >= 0 ? SyncStep::HandAxis : SyncStep::None;
      wait_ = Wait::HandAxis;
      if (j < 0) sync_done_edge_ = true;
      break;
    }
    default:  // pallet shuttle and anything else without a handshake here
      sync_done_edge_ = true;
      break;
  }
  if (sync_step_ != SyncStep::None && step_sync()) {
    sync_step_ = SyncStep::None;
    sync_done_edge_ = true;
  }
}

bool Servo::step_sync() noexcept {
  switch (sync_step_) {
    case SyncStep::ToolChanger:
      if (!in_.tool.changed) return false;
      tool_ = selected_tool_;  // M6 puts the tool the T word selected into the spindle
      prepared_tool_ = 0;
      return true;
    case SyncStep::ManualTool:
      if (!manual_tool_done_) return false;
      tool_ = selected_tool_;
      prepared_tool_ = 0;
      return true;
    case SyncStep::Input:
      return step_wait_input();
    case SyncStep::Orient:
      return in_.spindle.orient_done;
    case SyncStep::HandAxis:
      if (!hand_axis_there(false)) return false;
      hand_guard_ = true;  // from now on the run needs the axis to stay there
      return true;
    case SyncStep::None:
      return true;
  }
  return true;
}

double Servo::hand_position(int axis) const noexcept {
  const int j = joint_of(axis);
  return j >= 0 ? position_[static_cast<std::size_t>(j)] + offset_[static_cast<std::size_t>(j)] : 0.0;
}

// The hand axis is where the wait asks (HandWait): a retract at or above target − tolerance; a
// plunge reached at or below target + tolerance, and held within the tolerance of the target.
bool Servo::hand_axis_there(bool holding) const noexcept {
  const double x = hand_position(hand_wait_.axis);
  const double lo = hand_wait_.target - hand_wait_.tolerance, hi = hand_wait_.target + hand_wait_.tolerance;
  if (hand_wait_.retract) return x >= lo;
  return x <= hi && (!holding || x >= lo);
}

// While the automatic axes move after a hand-axis wait, the hand axis must stay where that wait
// put it (the drill must not come down while the table travels): if it leaves, feed hold; resume
// and cycle start are refused until it is back.
void Servo::check_hand_guard() noexcept {
  if (!hand_guard_ || aborting_ || hold_ || tick_out_.path_velocity == 0 || hand_axis_there(true)) return;
  hold_ = true;
  set_state(State::Held);
  ServoEvent e;
  e.kind = EventKind::HandAxisMoved;
  e.axis = hand_wait_.axis;
  e.value = hand_position(hand_wait_.axis);
  e.run_id = run_id_;
  emit(e);
}

// M66: L0 reads at once; L1 waits for a rising edge, L2 a falling one, L3 a high level, L4 a low
// one, at most `value` seconds (then the result is −1, as LinuxCNC's #5399).
bool Servo::step_wait_input() noexcept {
  const MachineAction& a = sync_action_;
  double result = 0;
  bool done = false;
  if (!a.digital) {
    const int ch = std::clamp(a.index, 0, machine::kAnalogChannels - 1);
    result = in_.analog_in[static_cast<std::size_t>(ch)];
    done = true;
  } else {
    const bool now = (in_.digital_in >> std::clamp(a.index, 0, 63)) & 1u;
    switch (a.index2) {
      case 1:
        done = now && !sync_input_before_;
        break;
      case 2:
        done = !now && sync_input_before_;
        break;
      case 3:
        done = now;
        break;
      case 4:
        done = !now;
        break;
      default:
        done = true;
        break;
    }
    sync_input_before_ = now;
    result = now ? 1.0 : 0.0;
  }
  const double waited = static_cast<double>(tick_ - sync_started_tick_) * config_.period_s;
  if (!done && a.value > 0 && waited >= a.value) {
    result = -1;
    done = true;
  }
  if (!done) return false;
  input_value_ = result;
  ServoEvent e;
  e.kind = EventKind::InputRead;
  e.run_id = run_id_;
  e.action = a.action;
  e.value = result;
  emit(e);
  return true;
}

// A probe move (G38.x) stops when the probe trips: the position is latched and the run ends
// with a controlled stop; the controller continues the program from where the machine stopped.
void Servo::check_probe() noexcept {
  if (!caps_.probe || aborting_) return;
  const traj::MotionBlock* b = block(tick_out_.block_seq);
  if (b == nullptr || (b->flags & traj::kProbe) == 0) return;
  if (b->seq != probe_seq_) {  // a new probe move: its result starts afresh
    probe_seq_ = b->seq;
    probe_tripped_ = false;
  }
  if (!in_.probe || probe_tripped_) return;
  probe_tripped_ = true;
  probe_run_ = run_id_;
  // Where the probe tripped: the machine's latch of the edge when it has one, else the middle of
  // the last two samples (the edge lies between them: half the error of either).
  const bool latched = probe_edge_latched_;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const double at = latched ? in_.probe_latch[uj] : 0.5 * (previous_feedback_[uj] + feedback_[uj]);
    probe_position_[config_.joints[uj].axis] = at + offset_[uj];
  }
  abort_edge_ = aborting_ = true;
  ServoEvent e;
  e.kind = EventKind::ProbeTripped;
  e.run_id = run_id_;
  e.segment = tick_out_.segment;
  emit(e);
}

void Servo::end_run(RunEnd why) noexcept {
  traj::BlockQueue& q = channels_->blocks;
  q.pop(q.available());
  channels_->actions.drop_until(~std::uint64_t{0});
  // Only this run's probe move stops it as a probe's stop: the latch of an earlier run's (the
  // electrode setting's touches) stays for the status, and an abort now is an abort.
  if (why == RunEnd::Aborted && probe_tripped_ && probe_run_ == run_id_) why = RunEnd::ProbeTripped;
  ServoEvent e;
  e.kind = EventKind::RunEnded;
  e.run_id = run_id_;
  e.run_end = why;
  e.segment = tick_out_.segment;
  emit(e);
  activity_ = Activity::None;
  release_coupling();  // a program's coupling lasts as long as its run
  gap_.begin_run(commanded_);  // and so does its machining condition (the generator goes off)
  torch_.begin_run();          // and the torch (its offset stays in the commanded position)
  hold_ = aborting_ = cycle_start_edge_ = abort_edge_ = sync_done_edge_ = false;
  sync_step_ = SyncStep::None;
  wait_ = Wait::None;
  hand_wait_ = HandWait{};
  hand_guard_ = false;
  reset_movers();
  if (why == RunEnd::Finished || why == RunEnd::Aborted || why == RunEnd::ProbeTripped)
    set_state(State::Idle);
  // Back to the origin after every part where the profile asks (the seed's way of keeping lost
  // steps from adding up): the joints home again, and the status tells how far the origin moved.
  if (why == RunEnd::Finished && run_mode_ == Mode::Auto) {
    std::uint16_t again = 0;
    for (int j = 0; j < config_.joint_count; ++j) {
      if (config_.joints[static_cast<std::size_t>(j)].home.return_after_program && !manual(j))
        again = static_cast<std::uint16_t>(again | (1u << j));
    }
    if (again != 0) start_homing(again);
  }
}

}  // namespace opencnc::control
