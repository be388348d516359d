// SPDX-License-Identifier: GPL-3.0-or-later
// ServoStatus — the snapshot the servo publishes every period, and TraceSample, the per-period
// record for traces and run reports. Plain fixed-size data.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

#include "opencnc/control/command.hpp"
#include "opencnc/control/edm_status.hpp"
#include "opencnc/control/homing.hpp"
#include "opencnc/control/limit_seek.hpp"
#include "opencnc/control/load_guard.hpp"
#include "opencnc/control/torch_status.hpp"
#include "opencnc/core/axes.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/process_alarms.hpp"
#include "opencnc/motion/coupling.hpp"
#include "opencnc/traj/interpolator.hpp"

namespace opencnc::control {

/// One joint's homing as the status shows it.
struct HomingStatus {
  HomingPhase phase = HomingPhase::Idle;
  bool measured = false;   ///< DecelMidpoint: the edges below are from the last homing
  double rising_edge = 0;  ///< interpolated edges, joint coordinates
  double falling_edge = 0;
  double width = 0;  ///< S = falling − rising
  /// How far the positions before the last homing were off: where the controller believed the
  /// axis was less where that homing found it (+ = believed further in +). Lost steps, or a
  /// reference that drifted, show here; 0 after the first homing.
  double origin_shift = 0;
};

/// One joint's seek of a limit switch as the status shows it (machine coordinates): the phase
/// while it runs, and what the last one found.
struct LimitSeekStatus {
  SeekPhase phase = SeekPhase::Idle;
  std::int8_t direction = 0;  ///< +1 / −1: the switch sought; 0 = no seek yet
  bool found = false;         ///< the last seek latched its switch
  double tripped_at = 0;      ///< where the switch tripped at latch velocity
  double released_at = 0;     ///< where it released on the way off
  double rest_at = 0;         ///< where the seek left the axis
};

/// A program waiting for a hand-fed axis (Wait::HandAxis), and then holding it there while the
/// table moves. A retract (the program moved the axis in +) is reached and held at or above
/// target − tolerance; a plunge is reached at or below target + tolerance and then held within
/// the tolerance of the target.
struct HandWait {
  std::int8_t axis = -1;  ///< Axis index, −1 = none
  double target = 0;      ///< machine position
  bool retract = false;   ///< the move went in + (up, away from the work)
  double tolerance = 0;
};

struct JointStatus {
  double commanded = 0;        ///< machine coordinates
  double actual = 0;           ///< feedback in machine coordinates
  double following_error = 0;  ///< reference − feedback, units
  double velocity = 0;         ///< commanded, units/s
  double effort = 0;           ///< the drive's force N or torque N·m, as it reports it
  bool effort_valid = false;   ///< the drive reports its effort (MachineCapabilities)
  bool homed = false;
  bool homing = false;
  bool limit_neg = false, limit_pos = false, home_switch = false, amp_fault = false;
};

/// The coupling stage now: the law a program engaged (kind Off: none) and where it engaged.
struct CouplingStatus {
  motion::CouplingKind kind = motion::CouplingKind::Off;
  std::int8_t master_axis = -1, slave_axis = -1;
  std::int32_t table = 0;      ///< 1-based table number (pitch table, cam)
  double pitch_mm = 0;         ///< constant pitch, or the pitch at engagement (linear law)
  double pitch_rate = 0;       ///< linear law: mm of pitch per mm of master travel
  double master_origin = 0;    ///< master's machine position at engagement
  double slave_origin = 0;     ///< slave's machine position at engagement
  double error_deg = 0;        ///< actual slave − law(actual master): the helix error now
};

struct ServoStatus {
  std::uint64_t tick = 0;
  double time_s = 0;  ///< tick × period
  State state = State::Off;
  Mode mode = Mode::Manual;
  Activity activity = Activity::None;
  Wait wait = Wait::None;
  StopReason stop_reason = StopReason::None;
  bool aborting = false;
  bool estop_input_ok = false;
  bool drives_enabled = false;

  int joint_count = 0;
  std::array<JointStatus, machine::kMaxJoints> joints{};
  Pose commanded{};  ///< every axis, machine coordinates
  Pose actual{};
  bool all_homed = false;

  // The run (Auto program or MDI line).
  std::uint32_t run_id = 0;  ///< the last run started (0 = none yet)
  Mode run_mode = Mode::Auto;
  bool run_active = false;
  traj::RunState motion = traj::RunState::Idle;  ///< the interpolator's state
  std::uint64_t segment = 0;                     ///< canon segment id at the commanded position
  std::uint64_t segment_first = 0;  ///< the first move the block there stands for (blends, merges)
  double segment_offset = 0;        ///< path length from the start of `segment` to the commanded position
  std::uint32_t line = 0;                        ///< its source line
  std::uint32_t context = 0;
  double path_velocity = 0;  ///< along the path, s-units/s
  /// The motion follows the spindle (G33, G76, G33.1): feed hold and the feed override do not act
  /// on it (an abort does).
  bool spindle_synced = false;

  // Operator switches.
  double feed_override = 1, rapid_override = 1, spindle_override = 1;
  bool single_block = false, optional_stop = false;

  // Machine outputs and what came back.
  double spindle_rpm = 0;  ///< commanded (after override)
  machine::SpindleDirection spindle_direction = machine::SpindleDirection::Stopped;
  double spindle_rpm_actual = 0;
  bool spindle_at_speed = false;
  double spindle_torque_nm = 0;       ///< the spindle drive's torque, N·m, as it reports it
  bool spindle_torque_valid = false;  ///< the drive reports its torque (MachineCapabilities)
  bool flood = false, mist = false;
  std::int32_t tool = 0;           ///< tool in the spindle
  std::int32_t prepared_tool = 0;  ///< tool brought to the change position
  std::uint64_t digital_out = 0;   ///< as written to the machine (the interlock rules' outputs included)
  std::array<double, machine::kAnalogChannels> analog_out{};
  bool mains_ok = true, on_battery = false;
  double dc_link_v = 0;
  /// Wait::Dwell at a coupling code (M171–M174): master and slave coming to stand on their
  /// commands before the law takes them ([coupling] engage_tolerance_um).
  bool coupling_wait = false;
  /// ½·C·(V² − V_min²) of the link the profile's [power] states, J (0: not stated).
  double dc_link_energy_j = 0;
  /// The last power-fail stop's deceleration, times the path's budget (1: as planned), until reset.
  double stop_decel_scale = 1;

  // Answers.
  Fault fault{};  ///< the fault that made the state Faulted (kind None otherwise)
  std::uint64_t last_command_id = 0;
  Refusal last_refusal = Refusal::None;
  std::uint64_t commands_accepted = 0, commands_refused = 0;
  std::uint64_t events_dropped = 0, trace_dropped = 0;
  bool probe_tripped = false;  ///< during the last probe move
  Pose probe_position{};       ///< actual position when it tripped
  double input_value = 0;      ///< the last M66 result (−1: timed out)

  // Homing, compensation, hand axes, interlocks, handwheel (the drill retrofit).
  std::array<HomingStatus, machine::kMaxJoints> homing{};
  std::array<LimitSeekStatus, machine::kMaxJoints> seek{};  ///< the seeks of the limit switches
  std::array<double, machine::kMaxJoints> compensation{};  ///< correction each joint gets now, units
  HandWait hand_wait{};                                    ///< what a Wait::HandAxis waits for
  /// The first `block spindle` rule holding now (what a Wait::Interlock waits on), −1 = none.
  std::int8_t interlock_rule = -1;
  std::uint32_t interlocks_true = 0;  ///< bit per rule whose condition holds
  std::uint16_t alarms_active = 0;    ///< bit per process alarm whose input is out of range
  /// Each process alarm's input as read this period (in its profile unit; 0 past the count).
  std::array<double, machine::kMaxProcessAlarms> alarm_values{};
  std::int8_t handwheel_axis = -1;    ///< the axis the handwheel moves (−1 = none)
  double handwheel_step = 0;          ///< units per count
  CouplingStatus coupling{};          ///< the axis coupling (broaching)
  // The load guard (broaching): the process load and what the guard did last in this run.
  double load_kn = 0;  ///< the load input now (0 without a load guard)
  LoadAction load_action = LoadAction::None;
  EdmStatus edm{};                    ///< the EDM gap servo, jump and orbit
  TorchStatus torch{};                ///< the plasma torch's sequence and height control
};

/// One servo period, for traces and run reports (docs/controller.md, "Trace CSV").
struct TraceSample {
  std::uint64_t tick = 0;
  State state = State::Off;
  Activity activity = Activity::None;
  traj::RunState motion = traj::RunState::Idle;
  bool rapid = false;  ///< the block at the commanded position is a rapid (G0)
  std::uint32_t run_id = 0;
  std::uint32_t line = 0;
  std::uint64_t segment = 0, segment_first = 0, segment_last = 0;
  double path_velocity = 0;
  Pose commanded{};        ///< machine coordinates, every axis
  Pose actual{};           ///< feedback in machine coordinates
  Pose following_error{};  ///< per axis
  Pose output{};           ///< what the drives were told, machine coordinates (with compensation)
  std::array<HomingPhase, kAxisCount> homing_phase{};  ///< per axis
  Pose home_level{};                                   ///< the home proximity sensor's level, per axis
  bool coupled = false;          ///< a coupling law held the slave in this period
  bool power_stop = false;       ///< a power-fail stop is under way (from the period after the signal)
  double coupling_error_deg = 0;  ///< actual slave − law(actual master), degrees (0 uncoupled)
  double load_kn = 0;             ///< the process load input (load guard), kN
  double dc_link_energy_j = 0;    ///< the link's usable energy (ServoStatus::dc_link_energy_j), J
  double stop_decel_scale = 1;    ///< the power-fail stop's deceleration scale (1: not in one)
  EdmStatus edm{};                ///< the EDM gap servo (machines with [edm])
  TorchStatus torch{};            ///< the plasma torch (machines with [process.plasma])
};

static_assert(std::is_trivially_copyable_v<ServoStatus>);
static_assert(std::is_trivially_copyable_v<TraceSample>);

}  // namespace opencnc::control
