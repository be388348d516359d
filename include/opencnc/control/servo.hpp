// SPDX-License-Identifier: GPL-3.0-or-later
// Servo — the real-time half of the controller: one tick() per servo period, from the machine's
// inputs to its outputs, in a fixed order of stages. Fixed-size state, no allocation, noexcept.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/control/axis_mover.hpp"
#include "opencnc/control/channels.hpp"
#include "opencnc/control/gap_servo.hpp"
#include "opencnc/control/homing.hpp"
#include "opencnc/control/limit_seek.hpp"
#include "opencnc/control/servo_config.hpp"
#include "opencnc/control/tickable.hpp"
#include "opencnc/control/torch_height.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/motion/compensation.hpp"
#include "opencnc/motion/pulse_distributor.hpp"
#include "opencnc/traj/interpolator.hpp"

namespace opencnc::control {

/// The servo tick. It owns the modes and state machines that must act within a period —
/// safety, homing, jogging, the interpolator of Auto and MDI runs, the machine handshakes of a
/// program's markers — and talks to the rest of the controller only through ServoChannels
/// (commands and motion blocks in; events, status and trace out). The state table it follows is
/// in docs/controller.md. It does not know which clock drives it.
class Servo final : public Tickable {
 public:
  /// Setup thread, before the first tick. `channels` and `machine` must outlive the servo.
  Servo(const ServoConfig& config, ServoChannels& channels, machine::MachineIO& machine) noexcept;
  Servo(const Servo&) = delete;
  Servo& operator=(const Servo&) = delete;

  /// One servo period, stage by stage (see the body). Servo thread; real-time safe, noexcept,
  /// allocates nothing. Always returns true (the clock decides when to stop).
  bool tick() noexcept override;

  /// Periods run. Servo thread (or any thread once the servo has stopped).
  std::uint64_t ticks() const noexcept { return tick_; }
  /// The state, and the id of the command applied last (accepted or not). Servo thread (tests that
  /// tick by hand measure with them how soon a command acts).
  State state() const noexcept { return state_; }
  std::uint64_t last_command_id() const noexcept { return last_command_id_; }
  const ServoConfig& config() const noexcept { return config_; }
  /// The compensation stage (its tables and corrections now). Servo thread, or any thread once
  /// the servo has stopped (tests in virtual time).
  const motion::Compensation& compensation() const noexcept { return comp_; }
  /// Forgets joint limits and pitch tables staged and not applied (a controller that staged them
  /// died before its ApplyJointLimits): the next apply takes only what is staged after this.
  /// Servo thread (SharedServoHost, when a new controller's set-up arrives); real-time safe.
  void drop_staged() noexcept {
    staged_joints_ = staged_tables_ = 0;
    staged_invalid_ = false;
  }

 private:
  using Joints = std::array<double, machine::kMaxJoints>;

  // --- stages of a period (servo.cpp) -------------------------------------------------------
  void read_inputs() noexcept;
  void check_safety() noexcept;
  void apply_interlocks() noexcept;
  void guard_load() noexcept;
  void check_process_alarms() noexcept;  // servo_alarms.cpp
  void trip_process_alarm(int index, double value, bool low) noexcept;
  void handle_commands() noexcept;
  bool next_command(Command& c, bool urgent_only) noexcept;
  void run_active_mode() noexcept;
  void couple_axes() noexcept;
  void compensate() noexcept;
  void check_soft_limits() noexcept;
  void write_outputs() noexcept;
  void publish() noexcept;

  void start_up() noexcept;
  void check_joint_faults() noexcept;
  bool check_stall(int j) noexcept;
  void check_power() noexcept;
  // --- the power-fail stop's deceleration (servo_power_stop.cpp) -----------------------------
  double dc_link_energy_j() const noexcept;
  double stop_scale_bound() const noexcept;
  void choose_stop_scale() noexcept;
  void follow_feedback() noexcept;
  void write_joint(int j) noexcept;
  void write_steppers() noexcept;
  void write_machine_outputs() noexcept;
  void write_spindle(bool on) noexcept;
  void fill_status(ServoStatus& s) const noexcept;
  void fill_drill_status(ServoStatus& s) const noexcept;
  void push_trace() noexcept;

  // --- transitions (servo_commands.cpp) -----------------------------------------------------
  Refusal apply(const Command& c) noexcept;
  Refusal need_on() const noexcept;
  Refusal reset() noexcept;
  Refusal machine_on() noexcept;
  Refusal machine_off() noexcept;
  Refusal set_mode(Mode m) noexcept;
  Refusal start_run(const Command& c) noexcept;
  Refusal cycle_start() noexcept;
  Refusal feed_hold() noexcept;
  Refusal resume() noexcept;
  Refusal abort() noexcept;
  Refusal set_override(double& target, double value, double max) noexcept;
  Refusal manual_spindle_or_coolant(const Command& c) noexcept;
  Refusal tool_changed() noexcept;
  Refusal set_handwheel(const Command& c) noexcept;

  // --- limits changed while idle (servo_limits.cpp) -----------------------------------------
  Refusal stage_joint_limits(const Command& c) noexcept;
  Refusal apply_joint_limits() noexcept;
  Refusal stage_pitch_table(const Command& c) noexcept;
  Refusal stage_edm_conditions() noexcept;
  void enter_estop() noexcept;
  void enter_fault(const Fault& f) noexcept;
  void halt(RunEnd why) noexcept;
  void set_state(State s) noexcept;
  void emit(const ServoEvent& e) noexcept;

  // --- manual mode: jogs and homing (servo_manual.cpp) --------------------------------------
  Refusal jog(const Command& c) noexcept;
  Refusal jog_stop(int axis) noexcept;
  Refusal home(int axis) noexcept;
  void run_movers() noexcept;
  void run_homing() noexcept;
  void start_next_homing_group() noexcept;
  void reset_movers() noexcept;
  int joint_of(int axis) const noexcept;
  bool toward_active_limit(int j, double direction) const noexcept;
  bool any_limit_switch() const noexcept;
  bool all_homed() const noexcept;
  bool manual(int j) const noexcept {
    return config_.joints[static_cast<std::size_t>(j)].drive == machine::JointDrive::Manual;
  }
  void run_handwheel() noexcept;
  void follow_hand_axes() noexcept;
  void start_homing(std::uint16_t joints) noexcept;
  void finish_homing(int j) noexcept;

  // --- seeking a limit switch (servo_seek.cpp) -----------------------------------------------
  Refusal seek_limit(const Command& c) noexcept;
  void run_seeks() noexcept;
  void cancel_seeks() noexcept;
  void end_seek(int j) noexcept;
  bool seeking(int j) const noexcept { return seeks_[static_cast<std::size_t>(j)].active(); }
  /// The seek's own switch is on and the other limit switch is not (that one would be a fault).
  bool sought_switch_only(int j) const noexcept;

  // --- interlocks (servo_interlocks.cpp) -----------------------------------------------------
  bool signal(const machine::RuleToken& t) const noexcept;
  bool holds(const machine::InterlockRule& r) const noexcept;
  void act_on_rule(int index, const machine::InterlockRule& r, bool now, bool before) noexcept;
  void emit_interlock(int index, CommandKind what) noexcept;
  bool spindle_may_start() const noexcept;

  // --- the load guard (servo_load_guard.cpp) ------------------------------------------------
  void step_load_retract() noexcept;
  void start_load_lift() noexcept;
  void emit_load(LoadAction a) noexcept;

  // --- axis coupling (servo_coupling.cpp) ----------------------------------------------------
  void engage_coupling(const MachineAction& a) noexcept;
  void release_coupling() noexcept;
  double coupling_master() const noexcept;
  double coupling_error() const noexcept;
  bool coupling_in_position() noexcept;
  void check_engage_wait() noexcept;

  // --- EDM gap servo, jump and orbit (servo_gap.cpp) ------------------------------------------
  void configure_gap_servo() noexcept;
  void run_gap_servo() noexcept;
  void watch_gap() noexcept;

  // --- plasma: the torch's sequence and its height control (servo_torch.cpp) ---------------------
  void run_torch_height() noexcept;

  // --- Auto and MDI runs (servo_program.cpp) ------------------------------------------------
  void run_program() noexcept;
  traj::TickInput program_inputs() noexcept;
  void apply_reports() noexcept;
  void report_sync_points() noexcept;
  void apply_action(const MachineAction& a) noexcept;
  bool take_action(std::uint32_t action, MachineAction& out) noexcept;
  void run_sync() noexcept;
  void begin_sync() noexcept;
  bool step_sync() noexcept;
  bool step_wait_input() noexcept;
  void check_probe() noexcept;
  bool hand_axis_there(bool holding) const noexcept;
  void check_hand_guard() noexcept;
  double hand_position(int axis) const noexcept;
  void map_program_state() noexcept;
  void end_run(RunEnd why) noexcept;
  const traj::MotionBlock* block(std::uint64_t seq) const noexcept;
  bool spindle_at_speed() const noexcept;
  bool spindle_change_pending() const noexcept;
  void stop_spindle_and_coolant() noexcept;

  ServoConfig config_;
  std::array<JointLimits, machine::kMaxJoints> staged_limits_{};  ///< StageJointLimits, not applied yet
  std::uint16_t staged_joints_ = 0;                               ///< bit j: joint j is staged
  std::uint16_t staged_tables_ = 0;  ///< bit j: joint j has a pitch table staged (StagePitchTable)
  std::array<std::uint8_t, machine::kMaxJoints> staged_buffer_{};  ///< which buffer is staged
  bool staged_conditions_ = false;  ///< StageEdmConditions: the channels' conditions wait for the apply
  bool staged_invalid_ = false;  ///< a stage was refused: the next apply refuses too (all or nothing)
  ServoChannels* channels_;
  machine::MachineIO* machine_;
  machine::MachineCapabilities caps_{};
  machine::MachineInputs in_{};
  machine::MachineOutputs out_{};
  std::uint64_t tick_ = 0;
  bool started_ = false;

  // State machine.
  State state_ = State::Off;
  State published_state_ = State::Off;
  Mode mode_ = Mode::Manual;
  Activity activity_ = Activity::None;
  Wait wait_ = Wait::None;
  StopReason stop_reason_ = StopReason::None;
  Fault fault_{};
  bool power_stop_ = false;  ///< a controlled stop for a power failure is under way
  /// The power-fail stop's deceleration: times the path's budget (1 = as planned), and the most
  /// the moving axes' peak decelerations allow (chosen at the signal).
  double stop_scale_ = 1, stop_scale_max_ = 1;
  /// A coupling code's wait for master and slave in position: periods they have stood within the
  /// tolerance, periods waited so far.
  int in_position_periods_ = 0;
  std::uint64_t engage_wait_periods_ = 0;
  std::uint64_t last_command_id_ = 0;
  std::uint64_t stop_seq_ = 0;  ///< the send order (Command::seq) of the latest stop applied
  Refusal last_refusal_ = Refusal::None;
  std::uint64_t accepted_ = 0, refused_ = 0, events_dropped_ = 0, trace_dropped_ = 0;

  // Positions. Machine coordinates = joint coordinates + offset (set by homing).
  Pose commanded_{};         ///< every axis, machine coordinates
  Joints joint_cmd_{};       ///< after coupling and compensation, joint coordinates
  Joints reference_{};       ///< what the drive aims at by the end of the period (cmd + ff·T)
  Joints joint_velocity_{};  ///< commanded, joint units/s (last two commands)
  Joints velocity_ff_{};     ///< what servo drives get of it (steppers: none)
  Joints feedback_{};        ///< joint coordinates (what the drive reports, compensation included)
  Joints position_{};        ///< feedback less the compensation: joint coordinates as commanded
  Joints following_error_{};
  Joints offset_{};
  std::array<bool, machine::kMaxJoints> homed_{};
  std::array<bool, machine::kMaxJoints> limit_active_{};  ///< either limit switch active
  std::array<bool, machine::kMaxJoints> limit_rising_{};  ///< ... and not in the last period
  bool drives_enabled_ = false;
  /// Compensation stage (pitch error, backlash): the correction each joint gets.
  motion::Compensation comp_;
  Joints compensation_{};    ///< the correction in the last outputs (feedback reflects it)
  bool moved_last_ = false;  ///< a driven joint's command changed in the last period

  // Axis coupling: the law a program engaged and where (CouplingStatus says the same).
  motion::CouplingLaw law_{};
  CouplingStatus coupling_{};
  int master_joint_ = -1, slave_joint_ = -1;

  // The load guard: the load now, periods above each level, the retract under way.
  enum class LoadRetract : std::uint8_t { None, Stopping, Lifting };
  double load_kn_ = 0;
  int hold_periods_ = 0, retract_periods_ = 0;
  LoadRetract load_retract_ = LoadRetract::None;
  LoadAction load_action_ = LoadAction::None;
  std::uint32_t load_run_id_ = 0;
  // Sinker EDM: the gap servo stage and the block it last saw at the interpolator's head.
  GapServo gap_;
  std::uint64_t gap_block_ = traj::kNoBlock;
  // Plasma: the torch stage.
  TorchHeight torch_;
  int torch_axis_ = -1;  ///< the axis the torch's offset is on (−1: no plasma)

  // Manual mode.
  std::array<AxisMover, machine::kMaxJoints> movers_{};
  std::array<JointHoming, machine::kMaxJoints> homing_{};
  std::uint16_t homing_pending_ = 0;  ///< joints still to home, by bit
  std::uint16_t homing_active_ = 0;   ///< joints homing now
  std::array<HomingStatus, machine::kMaxJoints> homing_status_{};
  std::array<LimitSeek, machine::kMaxJoints> seeks_{};
  std::array<LimitSeekStatus, machine::kMaxJoints> seek_status_{};
  std::uint16_t seeking_ = 0;  ///< a bit per joint whose seek runs
  std::array<double, machine::kMaxJoints> offset_before_homing_{};
  std::array<bool, machine::kMaxJoints> homed_once_{};
  std::int8_t handwheel_axis_ = -1;
  double handwheel_step_ = 0;
  std::int32_t handwheel_last_ = 0;

  // Runs.
  traj::Interpolator interp_;
  traj::TickOutput tick_out_{};
  std::uint32_t run_id_ = 0;
  Mode run_mode_ = Mode::Auto;
  bool hold_ = false;
  bool cycle_start_edge_ = false, abort_edge_ = false, sync_done_edge_ = false;
  bool released_ = false;  ///< cycle start reached the interpolator this period
  bool aborting_ = false;
  double feed_override_ = 1, rapid_override_ = 1, spindle_override_ = 1;
  bool single_block_ = false, optional_stop_ = false;
  enum class SyncStep : std::uint8_t { None, ToolChanger, ManualTool, Input, Orient, HandAxis };
  SyncStep sync_step_ = SyncStep::None;
  /// The Sync marker handled last: the tick after its release the commanded position may still
  /// show it while the interpolator already waits at the next one.
  std::uint64_t sync_seq_ = traj::kNoBlock;
  MachineAction sync_action_{};
  std::uint64_t sync_started_tick_ = 0;
  bool sync_input_before_ = false;
  bool manual_tool_done_ = false;
  bool probe_tripped_ = false;
  HandWait hand_wait_{};  ///< the hand-axis wait in progress, then its guard while the run moves
  bool hand_guard_ = false;
  std::uint64_t probe_seq_ = traj::kNoBlock;  ///< the probe move whose result probe_tripped_ is
  std::uint32_t probe_run_ = 0;               ///< the run in which probe_tripped_ was set
  Pose probe_position_{};
  std::uint32_t probe_edges_seen_ = 0;  ///< the machine's probe edge count at the last period
  bool probe_edge_latched_ = false;     ///< the machine latched a probe edge in this period
  Joints previous_feedback_{};          ///< feedback of the period before
  double input_value_ = 0;

  // Machine outputs the program and the operator set.
  double spindle_rpm_ = 0;
  machine::SpindleDirection spindle_direction_ = machine::SpindleDirection::Stopped;
  /// G96 constant surface speed: the highest rpm (D, 0 = off), the surface speed (mm/min) and
  /// the X (machine) of the spindle axis; the rpm follows X every period.
  double css_max_rpm_ = 0, css_surface_mm_min_ = 0, css_axis_x_ = 0;
  std::uint64_t spindle_changed_tick_ = 0;  ///< period of the last change of speed or direction
  bool spindle_override_enabled_ = true;
  bool orient_ = false;
  double orient_angle_ = 0;
  bool flood_ = false, mist_ = false;
  bool spindle_running_ = false;  ///< the spindle output turns (an interlock may hold a start back)
  std::int32_t tool_ = 0, selected_tool_ = 0, prepared_tool_ = 0, preparing_tool_ = 0;
  bool preparing_ = false;
  std::uint64_t digital_out_ = 0;
  std::array<double, machine::kAnalogChannels> analog_out_{};

  // Interlock rules: which conditions hold, and what they block now.
  std::uint32_t rules_true_ = 0;
  bool rules_started_ = false;
  bool motion_blocked_ = false, spindle_blocked_ = false, estop_rule_ = false;
  std::int8_t blocking_rule_ = -1;
  std::uint64_t rule_outputs_mask_ = 0, rule_outputs_ = 0;

  // Process alarms: a bit per alarm out of range; a feed-hold alarm out of range blocks starts.
  std::uint16_t alarms_active_ = 0;
  bool alarm_blocks_motion_ = false;

  // Stepper joints: one pulse distributor over all of them, slot per joint (−1 = servo).
  motion::PulseDistributor pulses_{motion::PulseMethod::Vector};
  std::array<std::int8_t, machine::kMaxJoints> stepper_slot_{};
  int stepper_count_ = 0;
};

}  // namespace opencnc::control
