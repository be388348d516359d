// SPDX-License-Identifier: GPL-3.0-or-later
// Servo: the stages of one servo period, in order, and the inputs/safety/outputs around them.
#include "opencnc/control/servo.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::control {

namespace {

/// Soft limits are checked with this slack (units), so that a move that ends exactly on a limit
/// is not a violation because of the last bit of rounding.
constexpr double kSoftLimitSlack = 1e-7;
/// Commands taken per period; the rest wait for the next one.
constexpr int kCommandsPerTick = 16;

static_assert(motion::kMaxCompensatedJoints == machine::kMaxJoints);

}  // namespace

Servo::Servo(const ServoConfig& config, ServoChannels& channels, machine::MachineIO& machine) noexcept
    : config_(config),
      channels_(&channels),
      machine_(&machine),
      caps_(machine.capabilities()),
      interp_(channels.blocks, config.interpolator, Pose{}) {
  config_.joint_count = std::clamp(std::min(config_.joint_count, caps_.joint_count), 0, machine::kMaxJoints);
  comp_ = motion::Compensation(config_.compensation);
  for (PitchBufferInUse& b : channels.pitch_tables.reading) b.index.store(-1, std::memory_order_release);
  configure_gap_servo();
  torch_.configure(config_.plasma, config_.period_s);
  torch_axis_ = torch_.enabled() ? config_.plasma.z_axis : -1;
  stepper_slot_.fill(-1);
  for (int j = 0; j < config_.joint_count; ++j) {
    const JointConfig& jc = config_.joints[static_cast<std::size_t>(j)];
    movers_[static_cast<std::size_t>(j)].configure(config_.period_s, jc.max_acceleration, jc.max_jerk, 0);
    if (jc.drive == machine::JointDrive::Stepper)
      stepper_slot_[static_cast<std::size_t>(j)] = static_cast<std::int8_t>(stepper_count_++);
  }
}

// The servo period. Its stages, in the order DESIGN.md fixes:
bool Servo::tick() noexcept {
  ++tick_;
  read_inputs();        // machine inputs (feedback, switches, power, spindle, I/O)
  check_safety();       // e-stop, limit switches, amplifier faults, stalls, following error, power
  apply_interlocks();   // the profile's interlock rules (the PLC): stops, holds, blocked starts
  check_process_alarms();  // analog process inputs out of range: message, feed hold, stop and fault
  guard_load();            // the process load: feed hold, or stop and retract (servo_load_guard.cpp)
  handle_commands();    // operator and controller commands: the explicit state transitions
  run_active_mode();    // homing / jog / handwheel (movers) or MDI / auto (interpolator, handshakes)
  run_gap_servo();      // EDM: along the path by the gap voltage, jump, orbit (servo_gap.cpp)
  run_torch_height();   // plasma: the cut's sequence, the height control's Z offset (servo_torch.cpp)
  couple_axes();        // axes → joints, a coupled slave by its law (servo_coupling.cpp)
  compensate();         // pitch error and backlash (motion::Compensation)
  check_soft_limits();  // every commanded joint within its soft limits
  write_outputs();      // position commands or step counts, enables, spindle, coolant, I/O
  publish();            // status snapshot, trace sample
  return true;
}

// --- read inputs -----------------------------------------------------------------------------

void Servo::read_inputs() noexcept {
  machine_->read(in_);
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const machine::JointInputs& ji = in_.joints[uj];
    previous_feedback_[uj] = feedback_[uj];
    feedback_[uj] = ji.position;
    position_[uj] = ji.position - compensation_[uj];
    following_error_[uj] = manual(j) ? 0.0 : reference_[uj] - feedback_[uj];
    const bool limit = ji.limit_neg || ji.limit_pos;
    limit_rising_[uj] = limit && !limit_active_[uj];
    limit_active_[uj] = limit;
  }
  probe_edge_latched_ = in_.probe_edges != probe_edges_seen_;
  probe_edges_seen_ = in_.probe_edges;
  if (!started_) start_up();
}

// First period: the machine's power-up position is the commanded one; joints that home
// immediately are homed where they stand; step counters start from the motors' counts.
void Servo::start_up() noexcept {
  started_ = true;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const JointConfig& jc = config_.joints[uj];
    if (jc.home.method == HomeMethod::Immediate) {
      offset_[uj] = jc.home.position - feedback_[uj];
      homed_[uj] = true;
    }
    if (stepper_slot_[uj] >= 0)
      pulses_.set_position(stepper_slot_[uj], std::llround(feedback_[uj] * jc.counts_per_unit));
    reference_[uj] = feedback_[uj];
    following_error_[uj] = 0;
  }
  handwheel_last_ = in_.handwheel_count;
  follow_feedback();
  reset_movers();
  state_ = published_state_ = in_.estop_ok ? State::Off : State::EStopped;
}

// While the drives are off the commanded position follows the machine, so that enabling them
// again moves nothing (the movers are reset where the motion starts again: machine on, halt).
void Servo::follow_feedback() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    commanded_[config_.joints[uj].axis] = position_[uj] + offset_[uj];
  }
}

// --- safety ----------------------------------------------------------------------------------

void Servo::check_safety() noexcept {
  if (!in_.estop_ok) {
    if (state_ != State::EStopped) enter_estop();
    return;
  }
  if (!drives_enabled_) return;
  check_joint_faults();
  if (drives_enabled_) check_power();
}

void Servo::check_joint_faults() noexcept {
  for (int j = 0; j < config_.joint_count && drives_enabled_; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const machine::JointInputs& ji = in_.joints[uj];
    const JointConfig& jc = config_.joints[uj];
    const double actual = position_[uj] + offset_[uj];
    if (manual(j)) continue;  // no drive: nothing to fault (a hand axis's switches are the operator's)
    if (check_stall(j)) return;
    if (ji.amp_fault) {
      enter_fault({FaultKind::AmpFault, jc.axis, actual, 0, tick_});
    } else if (limit_rising_[uj] && !(seeking(j) && sought_switch_only(j))) {
      enter_fault({activity_ == Activity::Homing ? FaultKind::Homing : FaultKind::LimitSwitch, jc.axis,
                   actual, 0, tick_});
    } else if (std::fabs(following_error_[uj]) > jc.max_following_error) {
      enter_fault({FaultKind::FollowingError, jc.axis, following_error_[uj], jc.max_following_error, tick_});
    }
  }
}

// A stepper drive that reports a stall has lost steps: its position is no longer known.
bool Servo::check_stall(int j) noexcept {
  const auto uj = static_cast<std::size_t>(j);
  if (!caps_.joints[uj].stall_detect || !in_.joints[uj].stall) return false;
  const JointConfig& jc = config_.joints[uj];
  enter_fault({FaultKind::Stall, jc.axis, position_[uj] + offset_[uj], 0, tick_});
  homed_[uj] = jc.home.method == HomeMethod::Immediate;
  return true;
}

// Mains lost or the UPS on battery: a controlled stop of whatever moves, then Faulted.
void Servo::check_power() noexcept {
  if (!caps_.power_monitor) return;
  const bool lost = !in_.power.mains_ok || (caps_.ups && in_.power.ups_on_battery);
  if (!lost || power_stop_) return;
  power_stop_ = true;
  stop_spindle_and_coolant();  // the process ends at once; the axes stop on the path (coupled)
  switch (activity_) {
    case Activity::Program:
      hold_ = false;
      abort_edge_ = aborting_ = true;
      stop_scale_ = 1;
      stop_scale_max_ = stop_scale_bound();
      break;
    case Activity::Homing:
    case Activity::Jog:
      cancel_seeks();
      for (int j = 0; j < config_.joint_count; ++j) {
        homing_[static_cast<std::size_t>(j)].cancel(movers_[static_cast<std::size_t>(j)]);
        movers_[static_cast<std::size_t>(j)].stop();
      }
      homing_pending_ = homing_active_ = 0;
      activity_ = Activity::Jog;  // the movers bring the joints to rest, then the fault
      break;
    case Activity::None:
      break;
  }
}

// --- commands --------------------------------------------------------------------------------

// Both queues in the order the controller sent their commands; past kCommandsPerTick the rest of
// the controller's queue waits, but the urgent one is always taken whole: a stop never waits a period.
bool Servo::next_command(Command& c, bool urgent_only) noexcept {
  auto& urgent = channels_->urgent;
  auto& queued = channels_->commands;
  const bool u = urgent.available() > 0;
  const bool q = !urgent_only && queued.available() > 0;
  if (u && (!q || urgent.front().seq < queued.front().seq)) return urgent.try_pop(c);
  return q && queued.try_pop(c);
}

void Servo::handle_commands() noexcept {
  Command c;
  constexpr int kMost = kCommandsPerTick + static_cast<int>(decltype(channels_->urgent)::kCapacity);
  for (int n = 0; n < kMost && next_command(c, n >= kCommandsPerTick); ++n) {
    const Refusal r = apply(c);
    last_command_id_ = c.id;
    last_refusal_ = r;
    ServoEvent e;
    e.kind = r == Refusal::None ? EventKind::Accepted : EventKind::Refused;
    e.command_id = c.id;
    e.command = c.kind;
    e.refusal = r;
    e.state = state_;
    e.run_id = c.run_id;
    emit(e);
    (r == Refusal::None ? accepted_ : refused_) += 1;
  }
}

// --- active mode -----------------------------------------------------------------------------

void Servo::run_active_mode() noexcept {
  switch (activity_) {
    case Activity::Program:
      run_program();
      break;
    case Activity::Homing:
      run_homing();
      break;
    case Activity::Jog:
      run_movers();
      break;
    case Activity::None:
      if (!drives_enabled_) follow_feedback();
      break;
  }
  run_handwheel();
  follow_hand_axes();
  if (power_stop_ && activity_ == Activity::None && drives_enabled_) {
    enter_fault({FaultKind::PowerLoss, -1, in_.power.dc_link_v, 0, tick_});
  }
}

// The correction of each driven joint (pitch error from the origin once homed, backlash on
// reversals, both taken up within the limits the planner left free); held while the drives are off
// (the command then follows the feedback less the correction, so that machine-on moves nothing).
void Servo::compensate() noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (manual(j)) continue;
    if (drives_enabled_) compensation_[uj] = comp_.update(j, joint_cmd_[uj], offset_[uj], homed_[uj]);
    joint_cmd_[uj] += compensation_[uj];
  }
}

void Servo::check_soft_limits() noexcept {
  if (!drives_enabled_) return;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const JointConfig& jc = config_.joints[uj];
    if (!homed_[uj] || jc.wrapped || activity_ == Activity::Homing || manual(j) || seeking(j)) continue;
    const double x = commanded_[jc.axis];
    const bool low = x<jc.min_limit - kSoftLimitSlack, high = x> jc.max_limit + kSoftLimitSlack;
    if (low || high) {
      enter_fault({FaultKind::SoftLimit, jc.axis, x, low ? jc.min_limit : jc.max_limit, tick_});
      couple_axes();
      return;
    }
  }
}

// --- outputs ---------------------------------------------------------------------------------

void Servo::write_outputs() noexcept {
  bool moved = false;
  for (int j = 0; j < config_.joint_count; ++j) {
    moved = moved ||
            (!manual(j) && drives_enabled_ &&
             joint_cmd_[static_cast<std::size_t>(j)] != out_.joints[static_cast<std::size_t>(j)].position);
    write_joint(j);
  }
  moved_last_ = moved;
  if (stepper_count_ > 0) write_steppers();
  write_machine_outputs();
  machine_->write(out_);
}

void Servo::write_joint(int j) noexcept {
  const auto uj = static_cast<std::size_t>(j);
  machine::JointOutputs& o = out_.joints[uj];
  if (manual(j)) {  // never commanded: the outputs only mirror the scale
    joint_velocity_[uj] = velocity_ff_[uj] = 0;
    reference_[uj] = o.position = feedback_[uj];
    o.velocity_ff = 0;
    o.enable = false;
    return;
  }
  const bool servo = config_.joints[uj].drive == machine::JointDrive::Servo;
  // Feed-forward from the last two commands: the drive extrapolates the reference with it over
  // the period (one period behind the true derivative, an error of a·T², 1 µm at 1000 mm/s²).
  joint_velocity_[uj] = drives_enabled_ ? (joint_cmd_[uj] - o.position) / config_.period_s : 0.0;
  velocity_ff_[uj] = servo ? joint_velocity_[uj] : 0.0;
  reference_[uj] = joint_cmd_[uj] + velocity_ff_[uj] * config_.period_s;
  o.position = joint_cmd_[uj];
  o.velocity_ff = velocity_ff_[uj];
  o.enable = drives_enabled_;
}

// Stepper joints: this period's whole-step increments are one straight move of the pulse
// distributor, run to its end (a step generator that pulls feed steps inside the period would
// call step() instead); the absolute counts go to the machine.
void Servo::write_steppers() noexcept {
  std::array<motion::StepCount, motion::kMaxPulseAxes> inc{};
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const int slot = stepper_slot_[uj];
    if (slot < 0) continue;
    const auto target =
        static_cast<motion::StepCount>(std::llround(joint_cmd_[uj] * config_.joints[uj].counts_per_unit));
    inc[static_cast<std::size_t>(slot)] = drives_enabled_ ? target - pulses_.position(slot) : 0;
  }
  if (pulses_.start(std::span<const motion::StepCount>(
          inc.data(), static_cast<std::size_t>(stepper_count_))) == motion::PulseStatus::Ok) {
    pulses_.advance(pulses_.feed_steps_total());
  }
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    if (stepper_slot_[uj] >= 0) out_.joints[uj].step_position = pulses_.position(stepper_slot_[uj]);
  }
}

void Servo::write_machine_outputs() noexcept {
  out_.estop_release = state_ != State::EStopped;
  const bool on = drives_enabled_;
  write_spindle(on);
  out_.process.flood = on && flood_;
  out_.process.mist = on && mist_;
  out_.process.generator_on = on && gap_.generator_on();
  out_.process.generator = gap_.generator();
  out_.process.torch_on = on && torch_.torch_on();
  if (preparing_ && in_.tool.prepared) {
    preparing_ = false;
    prepared_tool_ = preparing_tool_;
  }
  out_.tool.prepare = on && preparing_;
  out_.tool.prepare_tool = preparing_ ? preparing_tool_ : out_.tool.prepare_tool;
  out_.tool.change = on && sync_step_ == SyncStep::ToolChanger;
  out_.digital_out = (digital_out_ & ~rule_outputs_mask_) | (rule_outputs_ & rule_outputs_mask_);
  if (const int co = config_.plasma.cut_oxygen_output;
      co >= 0 && torch_.enabled()) {  // oxy-fuel: the torch stage's
    const std::uint64_t bit = std::uint64_t{1} << co;
    out_.digital_out =
        on && torch_.status().cut_oxygen ? (out_.digital_out | bit) : (out_.digital_out & ~bit);
  }
  out_.analog_out = analog_out_;
}

// The spindle's command. Under G96 the speed follows the commanded X every period, as
// LinuxCNC's motion does: rpm = v / (2π·|X − X_axis|) with v the surface speed (mm/min), the
// override applied, then the G96 D limit, then the spindle's own maximum; on the axis itself the
// D limit. A rigid tap (G33.1) turns it the other way from the bottom of the hole until the tap
// is out, at its I factor times the speed.
void Servo::write_spindle(bool on) noexcept {
  const double ovr = spindle_override_enabled_ ? spindle_override_ : 1.0;
  double rpm = spindle_rpm_ * ovr;
  if (css_max_rpm_ > 0) {
    constexpr double kTwoPi = 6.283185307179586;
    const double radius = std::fabs(commanded_[Axis::X] - css_axis_x_);
    rpm = radius > 0 ? css_surface_mm_min_ / (kTwoPi * radius) * ovr : css_max_rpm_;
    rpm = std::min(rpm, css_max_rpm_);
  }
  machine::SpindleDirection dir = spindle_direction_;
  if (activity_ == Activity::Program && tick_out_.tap_reverse) {
    rpm *= tick_out_.tap_speed_scale;
    if (dir == machine::SpindleDirection::Clockwise)
      dir = machine::SpindleDirection::Counterclockwise;
    else if (dir == machine::SpindleDirection::Counterclockwise)
      dir = machine::SpindleDirection::Clockwise;
  }
  if (config_.spindle_max_rpm > 0) rpm = std::min(rpm, config_.spindle_max_rpm);
  // A start waits while an interlock rule blocks it; a spindle that runs is not stopped by that.
  if (!on || spindle_direction_ == machine::SpindleDirection::Stopped) {
    spindle_running_ = false;
  } else if (!spindle_running_ && spindle_may_start()) {
    spindle_running_ = true;
  }
  out_.spindle.speed_rpm = on ? rpm : 0.0;
  out_.spindle.direction = on && spindle_running_ ? dir : machine::SpindleDirection::Stopped;
  out_.spindle.orient = on && orient_;
  out_.spindle.orient_angle_deg = orient_angle_;
}

// --- status ----------------------------------------------------------------------------------

void Servo::publish() noexcept {
  if (state_ != published_state_) {
    published_state_ = state_;
    ServoEvent e;
    e.kind = EventKind::StateChanged;
    e.state = state_;
    emit(e);
  }
  fill_status(channels_->status.back());
  channels_->status.publish();
  if (channels_->trace_enabled.load(std::memory_order_relaxed)) push_trace();
}

void Servo::fill_status(ServoStatus& s) const noexcept {
  s.tick = tick_;
  s.time_s = static_cast<double>(tick_) * config_.period_s;
  s.state = state_;
  s.mode = mode_;
  s.activity = activity_;
  s.wait = wait_;
  s.stop_reason = stop_reason_;
  s.aborting = aborting_ || power_stop_;
  s.estop_input_ok = in_.estop_ok;
  s.drives_enabled = drives_enabled_;
  s.joint_count = config_.joint_count;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const machine::JointInputs& ji = in_.joints[uj];
    JointStatus& js = s.joints[uj];
    js.commanded = commanded_[config_.joints[uj].axis];
    js.actual = position_[uj] + offset_[uj];
    js.following_error = following_error_[uj];
    js.velocity = joint_velocity_[uj];
    js.effort_valid = caps_.joints[uj].effort;
    js.effort = js.effort_valid ? ji.effort : 0.0;
    js.homed = homed_[uj];
    js.homing = (homing_active_ | homing_pending_) & (1u << j);
    js.limit_neg = ji.limit_neg;
    js.limit_pos = ji.limit_pos;
    js.home_switch = ji.home;
    js.amp_fault = ji.amp_fault;
    s.actual[config_.joints[uj].axis] = js.actual;
  }
  s.commanded = commanded_;
  s.all_homed = all_homed();
  s.run_id = run_id_;
  s.run_mode = run_mode_;
  s.run_active = activity_ == Activity::Program;
  s.motion = tick_out_.state;
  s.segment = tick_out_.segment;
  s.segment_first = tick_out_.segment_first;
  s.segment_offset = tick_out_.segment_offset;
  s.line = tick_out_.line;
  s.context = tick_out_.context;
  s.path_velocity = activity_ == Activity::Program ? tick_out_.path_velocity : 0.0;
  s.spindle_synced = activity_ == Activity::Program && tick_out_.spindle_synced;
  s.feed_override = feed_override_;
  s.rapid_override = rapid_override_;
  s.spindle_override = spindle_override_;
  s.single_block = single_block_;
  s.optional_stop = optional_stop_;
  s.spindle_rpm = out_.spindle.speed_rpm;
  s.spindle_direction = out_.spindle.direction;
  s.spindle_rpm_actual = in_.spindle.speed_rpm;
  s.spindle_at_speed = spindle_at_speed();
  s.spindle_torque_valid = caps_.spindle_torque;
  s.spindle_torque_nm = caps_.spindle_torque ? in_.spindle.torque_nm : 0.0;
  s.flood = out_.process.flood;
  s.mist = out_.process.mist;
  s.tool = tool_;
  s.prepared_tool = prepared_tool_;
  s.digital_out = out_.digital_out;  // what the machine is told (rules' outputs included)
  s.analog_out = analog_out_;
  s.mains_ok = in_.power.mains_ok;
  s.on_battery = in_.power.ups_on_battery;
  s.dc_link_v = in_.power.dc_link_v;
  s.coupling_wait = activity_ == Activity::Program && tick_out_.waiting_in_position;
  s.dc_link_energy_j = dc_link_energy_j();
  s.stop_decel_scale = stop_scale_;
  s.fault = fault_;
  s.last_command_id = last_command_id_;
  s.last_refusal = last_refusal_;
  s.commands_accepted = accepted_;
  s.commands_refused = refused_;
  s.events_dropped = events_dropped_;
  s.trace_dropped = trace_dropped_;
  s.probe_tripped = probe_tripped_;
  s.probe_position = probe_position_;
  s.input_value = input_value_;
  fill_drill_status(s);
}

void Servo::fill_drill_status(ServoStatus& s) const noexcept {
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    s.seek[uj] = seek_status_[uj];
    s.seek[uj].phase = seeks_[uj].phase();
    s.homing[uj] = homing_status_[uj];
    s.homing[uj].phase = homing_[uj].phase();
    s.compensation[uj] = compensation_[uj];
  }
  s.hand_wait = hand_wait_;
  s.interlock_rule = blocking_rule_;
  s.interlocks_true = rules_true_;
  s.alarms_active = alarms_active_;
  for (int i = 0; i < config_.alarms.count && i < machine::kMaxProcessAlarms; ++i) {
    const int ch = config_.alarms.alarms[static_cast<std::size_t>(i)].channel;
    s.alarm_values[static_cast<std::size_t>(i)] =
        ch >= 0 && ch < machine::kAnalogChannels ? in_.analog_in[static_cast<std::size_t>(ch)] : 0.0;
  }
  s.handwheel_axis = handwheel_axis_;
  s.coupling = coupling_;
  s.coupling.error_deg = coupling_error();
  s.edm = gap_.status();
  s.torch = torch_.status();
  s.handwheel_step = handwheel_step_;
  s.load_kn = load_kn_;
  s.load_action = load_action_;
}

void Servo::push_trace() noexcept {
  TraceSample t;
  t.tick = tick_;
  t.state = state_;
  t.activity = activity_;
  t.run_id = run_id_;
  const bool program = activity_ == Activity::Program;
  t.motion = program ? tick_out_.state : traj::RunState::Idle;
  const traj::MotionBlock* b = program ? block(tick_out_.block_seq) : nullptr;
  t.rapid = b != nullptr && b->kind != traj::BlockKind::Marker && b->feed_class == traj::FeedClass::Rapid;
  t.line = program ? tick_out_.line : 0;
  t.segment = tick_out_.segment;
  t.segment_first = tick_out_.segment_first;
  t.segment_last = tick_out_.segment_last;
  t.path_velocity = program ? tick_out_.path_velocity : 0.0;
  t.commanded = commanded_;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const int axis = config_.joints[uj].axis;
    t.actual[axis] = position_[uj] + offset_[uj];
    t.following_error[axis] = following_error_[uj];
    t.output[axis] = manual(j) ? t.actual[axis] : joint_cmd_[uj] + offset_[uj];
    t.homing_phase[static_cast<std::size_t>(axis)] = homing_[uj].phase();
    t.home_level[axis] = in_.joints[uj].home_level;
  }
  t.coupled = law_.active();
  t.power_stop = power_stop_;
  t.coupling_error_deg = coupling_error();
  t.load_kn = load_kn_;
  t.dc_link_energy_j = dc_link_energy_j();
  t.stop_decel_scale = power_stop_ ? stop_scale_ : 1.0;
  t.edm = gap_.status();
  t.torch = torch_.status();
  if (!channels_->trace.try_push(t)) ++trace_dropped_;
}

void Servo::emit(const ServoEvent& e) noexcept {
  ServoEvent copy = e;
  copy.tick = tick_;
  if (!channels_->events.try_push(copy)) ++events_dropped_;
}

}  // namespace opencnc::control
