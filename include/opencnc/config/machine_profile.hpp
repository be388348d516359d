// SPDX-License-Identifier: GPL-3.0-or-later
// MachineProfile: the validated description of a machine, as plain structs (no TOML types).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "opencnc/core/axes.hpp"
#include "opencnc/core/axis_map.hpp"
#include "opencnc/core/vec3.hpp"
#include "opencnc/kinematics/kinematics.hpp"
#include "opencnc/machine/interlocks.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/process_alarms.hpp"
#include "opencnc/machine/sim_config.hpp"

namespace opencnc::config {

enum class HomingMethod : std::uint8_t {
  Immediate,      ///< no motion: the present position becomes `position`
  Switch,         ///< search the home switch, back off, approach it slowly, latch its edge
  SwitchIndex,    ///< as Switch, then latch the next encoder index mark
  Index,          ///< latch the next encoder index mark (no switch)
  DecelHome,      ///< fast to the deceleration dog, slow on it until the home (proximity) switch
  DecelMidpoint,  ///< past the dog, back in the working direction: the middle of the proximity
                  ///< sensor's on-zone, both edges interpolated between periods
};

struct HomingProfile {
  HomingMethod method = HomingMethod::Immediate;
  double position = 0;         ///< machine position of the axis once homed
  double switch_position = 0;  ///< machine position of the latched switch edge or index mark
  double search_velocity = 0;  ///< units/s; the sign is the direction of the search
  double latch_velocity = 0;   ///< units/s; the sign is the direction of the latch move
  double final_velocity = 0;   ///< units/s for the move to `position` (0 = max_velocity)
  int sequence = 0;            ///< lower sequences home first; equal ones together
  // decel_midpoint: search_velocity is Vc toward the dog, return_velocity Vm the other way (the
  // working feed's direction), latch_velocity Vp the same way as Vm.
  double return_velocity = 0;         ///< units/s, signed, opposite to search_velocity
  double overrun = 0;                 ///< units travelled past the dog's edge before reversing
  bool return_after_program = false;  ///< home again after every program that ends (M2/M30)
};

/// The seek-limit move of an axis (keys of `[axis.<letter>.switches]`): at `velocity` to a limit
/// switch, off it and onto it again at `latch_velocity` (that trip is the one reported), then
/// `back_off` past where it released (docs/machine.md, "Seeking a limit switch").
struct LimitSeekProfile {
  double overtravel = 0;      ///< units past a limit switch's trip point before the hard stop
  double velocity = 0;        ///< seek_velocity, units/s; 0 = the axis has no seek
  double latch_velocity = 0;  ///< seek_latch_velocity, units/s
  double back_off = 0;        ///< seek_back_off, units beyond where the switch released
};

/// Most points of a pitch-error table (motion::kMaxPitchPoints, LinuxCNC's 256 too).
inline constexpr int kMaxCompensationPoints = 256;

/// Lead-screw and backlash compensation of one axis (`[axis.<letter>.compensation]`).
/// Tables hold the measured error (actual − nominal, units) at machine positions.
struct CompensationProfile {
  bool present = false;
  double backlash = 0;             ///< units
  double takeup_velocity = 0;      ///< limit of the correction's own motion, units/s
  double takeup_acceleration = 0;  ///< units/s²
  std::vector<double> positions;   ///< increasing; empty = no pitch table
  std::vector<double> forward;     ///< error moving in +
  std::vector<double> reverse;     ///< error moving in − (== forward for one table)
  bool one_table = false;          ///< written as `errors` (both directions), not forward/reverse
  std::string comp_file;           ///< the LinuxCNC comp file the table came from, as written; "" none
  int comp_file_type = 0;          ///< comp_file_type: 0 positions reached, 1 trims (−error)
  std::string comp_path;           ///< comp_file resolved against the profile's folder
  std::uint64_t comp_digest = 0;   ///< text_digest() of the comp file's text as loaded
};

/// One axis (= one joint: joints are numbered in axis order X Y Z A B C U V W).
struct AxisProfile {
  Axis axis = Axis::X;
  int joint = 0;
  bool rotary = false;          ///< A, B, C: degrees; the others mm
  bool wrapped = false;         ///< rotary axis that turns without end (no soft limits)
  double max_velocity = 0;      ///< units/s
  double max_acceleration = 0;  ///< units/s²
  double max_jerk = 0;          ///< units/s³; 0 = no jerk limit
  /// Units/s² the drive can brake the axis at in an emergency stop (≥ max_acceleration; 0 =
  /// not stated: no harder than max_acceleration). A power-fail stop short of energy uses it.
  double peak_deceleration = 0;
  double min_limit = 0;         ///< soft limits, machine coordinates
  double max_limit = 0;
  double max_following_error = 1;  ///< units; more is a fault
  machine::JointDrive drive = machine::JointDrive::Servo;
  double counts_per_unit = 1000;  ///< encoder counts (servo) or steps (stepper) per unit
  HomingProfile homing;
  machine::SwitchLayout switches;  ///< which switches exist, and where (the sim uses where)
  LimitSeekProfile seek;           ///< the move that seeks the limit switches
  machine::SimJointModel sim;      ///< mechanics and drive of the simulated axis
  bool stall_detector = false;     ///< stepper: the drive reports stalls (a fault)
  /// Manual axis: how close to a programmed position the operator must bring it, units.
  double hand_tolerance = 0.05;
  CompensationProfile compensation;

  bool manual() const noexcept { return drive == machine::JointDrive::Manual; }
};

struct SpindleProfile {
  bool present = false;
  double min_rpm = 0;
  double max_rpm = 0;
  /// The drive's rated (continuous) torque, N·m: the spindle's LOAD is its torque over this, in %
  /// (100 % = the rating, as spindle-load meters show it). 0 = not stated: no LOAD.
  double rated_torque_nm = 0;
  machine::SimSpindleConfig sim;  ///< max_rpm, encoder and orient copied in; the rest sim-only
};

struct PowerProfile {
  bool monitor = false;         ///< the machine reports mains, UPS and DC link
  machine::SimPowerConfig sim;  ///< ups, voltages, and the simulated supply
  /// The drives' common DC link as the machine states it (`[power]`; 0 = not stated: a power-fail
  /// stop is never shortened): its capacitance, F, and the power its standing load draws, W
  /// (the drives' electronics and whatever else hangs on it). The simulation's link defaults to it.
  double dc_link_capacitance_f = 0;
  double dc_link_idle_power_w = 0;
  /// A resume after a power failure, as offered to the operator (who may change them): how far
  /// the axes may stand from the breakpoint (mm, degrees), the run-in and its speed.
  double resume_tolerance_mm = 0.01, resume_tolerance_deg = 0.01;
  double resume_run_in_mm = 2.0, resume_run_in_speed_mm_min = 600;
};

/// `[probe.reference_sphere]`: the sphere electrodes are set against (docs/electrode-setting.md).
/// Machine coordinates, mm; feeds mm/min.
struct ReferenceSphereProfile {
  bool present = false;
  Vec3 position{};  ///< the sphere's centre (with B at `b_deg` on a machine with B)
  double diameter = 0;
  double b_deg = 0;            ///< the B angle the routine turns to first (machines with B)
  double clearance = 1;        ///< each touch starts this far off the surface and probes as far past it
  double probe_feed = 30;      ///< the touches' feed (the slow touch's, with fast_feed)
  /// Each direction approaches at this feed, backs off `back_off` from the contact and touches
  /// again at probe_feed (the slow touch's latch is used); 0: one touch at probe_feed.
  double fast_feed = 0;
  double back_off = 0.1;       ///< mm, the slow touch starts this far back from the fast one's contact
  double safe_z = 0;           ///< machine Z of the controlled point for moves between touches
  int touches_around = 4;      ///< touches around the equator (≥ 4), then one from above
  double tolerance = 0.002;    ///< largest |residual| of the fit
  double max_deviation = 1.0;  ///< largest change of the offsets from the table's (the sphere "too far")
  /// B's axis of rotation as the machine's drawing gives it, or as `opencnc calibrate-b` measured
  /// it: the line along the unit vector `b_axis_direction` (about Y) that crosses the plane of
  /// the sphere's centre (Y = position's) at X, Z `b_axis`. +B turns right-handed about it. The
  /// electrode setting reads it to find the sphere at any B (absent: only at `b_deg`).
  bool has_b_axis = false;
  std::array<double, 2> b_axis{};
  Vec3 b_axis_direction{0, 1, 0};
  bool sim = false;            ///< the simulated probe touches this sphere
  double sim_hysteresis = 0.0005;
  double sim_noise = 0.0002;
  /// The simulated sphere turns with B (a machine with B): about the line along
  /// `sim_b_direction` through machine X, Z `sim_b_axis` at the sphere's Y (the true axis, which
  /// the controller does not know; `position` is its centre with B at `b_deg`).
  bool sim_turns_with_b = false;
  std::array<double, 2> sim_b_axis{};
  Vec3 sim_b_direction{0, 1, 0};
};

struct ProbeProfile {
  bool present = false;
  int sim_joint = -1;  ///< joint whose table position trips the simulated probe
  machine::SwitchWindow sim_trip;
  double sim_hysteresis = 0.002;
  double sim_noise = 0.0005;
  ReferenceSphereProfile reference_sphere;
};

/// `[process.cutting]`: how a flame or plasma torch is put out and lit again (the retrace
/// feature's sequences, docs/retrace.md). Outputs are digital output channels (M64/M65 P);
/// heights are machine Z, mm; times in seconds.
struct CuttingProfile {
  bool present = false;
  int torch_output = -1;      ///< ignition and fuel gas (flame) or the arc (plasma)
  int preheat_output = -1;    ///< preheat oxygen (flame), −1: none
  int cut_output = -1;        ///< cutting oxygen (flame), −1: none
  double ignite_s = 0;        ///< torch on → flame established
  double preheat_s = 0;       ///< preheat at the pierce height before the cutting oxygen
  double pierce_s = 0;        ///< cutting oxygen on, torch still at the pierce height
  double safe_height_mm = 0;  ///< Z for moves to and from the path
  bool has_safe_height = false;
  double pierce_lift_mm = 0;  ///< pierce this much above the path's Z
  double approach_mm_min = 0;  ///< speed of the move to the path (0: rapid)
  double retrace_mm_min = 1000;  ///< speed of stepping along the path while paused
};

/// How a program's small holes are cut (`[process.plasma.holes]`, QtPlasmaC's hole settings: a
/// program pass, docs/cutting.md): closed contours of at most `diameter_mm` across run at
/// `speed_share` of their feed with the height held, go on `overcut_mm` past their end, and the
/// torch goes out `arc_off_mm` before the overcut's end. diameter_mm 0: no hole handling.
struct PlasmaHoles {
  double diameter_mm = 0;
  double speed_share = 0.6;
  double overcut_mm = 0;
  double arc_off_mm = 0;
};

/// `[process.plasma]`: the torch's sequence and height control (`config`, for the tick), the
/// holes (a program pass), the simulated plate and arc (`sim`; present: false without one).
struct PlasmaProfile {
  bool present = false;
  machine::PlasmaConfig config;
  PlasmaHoles holes;
  machine::SimPlasmaConfig sim;
};

/// Generic I/O channel counts (M62–M68, M66). Channels 0 … n-1 exist.
struct IoProfile {
  int digital_inputs = 4, digital_outputs = 4;
  int analog_inputs = 4, analog_outputs = 4;
};

/// A digital channel the interlock rules name.
struct NamedSignal {
  std::string name;
  int channel = 0;
};

/// `[interlocks]`: named inputs and outputs and the compiled rules (docs/machine.md).
struct InterlockProfile {
  std::vector<NamedSignal> inputs, outputs;
  std::vector<std::string> rule_texts;  ///< as written, for messages
  machine::InterlockRules rules;
};

/// `[alarms.<name>]`: analog process inputs with bounds and a reaction (docs/machine.md).
struct AlarmProfile {
  std::vector<std::string> names;  ///< in profile order, for messages
  std::vector<std::string> units;  ///< each alarm's unit as written ("" = none), for messages
  /// The simulated input's value at power-up, per analog channel (`sim` of an alarm; else 0).
  std::array<double, machine::kAnalogChannels> sim_values{};
  machine::ProcessAlarms alarms;
};

/// `[handwheel]`: a manual pulse generator for the driven axes.
struct HandwheelProfile {
  bool present = false;
  std::vector<double> steps{0.001, 0.01, 0.1};  ///< units per count the operator may select
};

enum class Dialect : std::uint8_t { LinuxCnc, Fanuc };
/// How Fanuc programs read: lathe conventions (X diameter, U/W, T0101, G50 S) or a mill's.
enum class MachineKind : std::uint8_t { Mill, Lathe };

struct InterpreterOptions {
  Dialect dialect = Dialect::LinuxCnc;
  MachineKind machine = MachineKind::Mill;
  AxisMap axis_map = identity_axis_map();    ///< program axis letter → machine axis
  std::vector<std::string> subroutine_path;  ///< folders searched for O-word subroutines
  std::string tool_table;                    ///< tool table file; empty = none
  /// How far the interpreter reads ahead of the machine while a program runs, in moves and in
  /// seconds of programmed motion (whichever comes first; never less than the planner needs).
  int readahead_moves = 2000;
  double readahead_s = 5.0;
  /// CPU seconds a program's check (the preflight, run from line's scan) may take before it is
  /// refused as an endless loop (gcode.limit-time); raise it for a program that long.
  double max_scan_s = 5.0;
};

/// One `[[coupling.table]]`: points [master offset mm, value] — pitch (mm per revolution) for a
/// pitch table, slave offset (degrees) for a cam. Numbered 1, 2, … in file order.
struct CouplingTableProfile {
  enum class Kind : std::uint8_t { Pitch, Cam };
  Kind kind = Kind::Pitch;
  std::vector<std::pair<double, double>> points;
};

/// `[coupling]`: the slave axis programs couple to a master (M171-M175, docs/broaching.md).
struct CouplingProfile {
  bool present = false;
  Axis master = Axis::Z;
  Axis slave = Axis::C;
  bool from_actual = false;  ///< the tick couples to the master's feedback instead of its command
  double radius_mm = 50;     ///< where helix errors are measured (the bore's radius)
  /// A coupling code waits until master and slave stand within this of their commands (µm: of the
  /// master's travel and of the slave's arc at radius_mm; 0: no wait) before the law takes them,
  /// at most engage_timeout_s (then the run stops with a fault).
  double engage_tolerance_um = 0.25;
  double engage_timeout_s = 2;
  std::vector<CouplingTableProfile> tables;
};

/// `[process.broaching]`: the broach's load cell, the levels at which the tick holds the feed or
/// retracts the cutter, the process-data log's rate, and (`[process.broaching.sim]`) the bore and
/// the cutter the simulated machine derives the load from (docs/broaching.md).
struct BroachingProfile {
  bool present = false;
  int load_input = 0;            ///< analog input channel of the load, kN
  double hold_kn = 0;            ///< feed hold above this (0: none)
  double retract_kn = 0;         ///< stop and retract above this (0: none)
  double confirm_s = 0.003;      ///< how long a level must be passed before it acts
  Axis radial = Axis::X;         ///< the axis that feeds the cutter out and lifts it
  double retract_lift = -0.5;    ///< signed lift along the radial axis, mm
  double retract_speed = 0;      ///< mm/s (0: the axis' maximum)
  double log_rate_hz = 100;      ///< rows per second of the process-data log
  machine::SimBroachConfig sim;  ///< the load model (sim.present: [process.broaching.sim] exists)
};

/// `[edm]`: a sinker EDM's machining conditions and gap servo (the tick's copy, plain data) and
/// its simulated spark gap `[edm.sim]` (docs/edm.md).
struct EdmProfile {
  bool present = false;
  machine::EdmConfig config;
  machine::SimEdmConfig sim;
};

/// `[tool_guard]`: the tool store and the check of its live table against the backup.
struct ToolGuardProfile {
  bool present = false;
  std::string store;                 ///< the SQLite tool store (relative to the profile)
  bool check_at_start = true;        ///< before every program start
  bool check_at_tool_change = true;  ///< at every M6, for the tool put in the spindle
  double geometry_tolerance_mm = 0.001;
  double base_tolerance_mm = 0.001;
  double wear_band_mm = 0.1;
  int check_mcode = 160;  ///< M-code of the on-demand check from G-code (0: none)
};

/// `[tool_change]`: where M6 takes the machine before the change, in machine coordinates
/// (docs/tool-change.md); given to the interpreter as gcode::Options::tool_change.
struct ToolChangeProfile {
  AxisMask axes;        ///< the axes `position` names (none: M6 does not move)
  Pose position{};      ///< mm, degrees for rotary axes
  bool z_first = true;  ///< Z alone first, then the others together
  std::string where;    ///< "file:line:col" of `position` (for messages)
};

struct PlannerOptions {
  int lookahead = 200;              ///< moves in the look-ahead window
  double default_tolerance = 0.01;  ///< mm: path tolerance while a program sets no G64 P
};

struct MachineProfile {
  std::string name;
  std::string description;
  std::string source;  ///< file the profile was read from
  std::vector<std::string> overrides;  ///< the `--set key=value` overrides it was read with
  std::uint64_t source_digest = 0;     ///< FNV-1a of the text it was read from (edits check it)
  double servo_period_s = 0.001;
  std::vector<AxisProfile> axes;  ///< in joint order
  SpindleProfile spindle;
  PowerProfile power;
  ProbeProfile probe;
  bool tool_changer = false;
  /// Pockets of the magazine (0: not said); the tool guard checks the tools' pockets against it.
  int tool_changer_pockets = 0;
  machine::SimToolChangerConfig tool_changer_sim;
  ToolChangeProfile tool_change;
  machine::SimProcessConfig process;  ///< torch / generator flags and their simulation
  CuttingProfile cutting;             ///< [process.cutting]: torch sequences for retrace
  PlasmaProfile plasma;               ///< [process.plasma]: the plasma torch, its THC, its simulation
  IoProfile io;
  InterlockProfile interlocks;
  AlarmProfile alarms;
  HandwheelProfile handwheel;
  CouplingProfile coupling;
  BroachingProfile broaching;
  EdmProfile edm;
  /// Digital inputs the simulated machine drives from switches (named inputs with a `sim`).
  std::vector<machine::SimInputSwitch> sim_input_switches;
  double sim_temperature_c = 20;  ///< machine temperature in the simulation
  InterpreterOptions interpreter;
  ToolGuardProfile tool_guard;
  PlannerOptions planner;
  /// [kinematics]: how the rotary axes turn the tool (identity when the section is absent).
  kinematics::Config kinematics;
  int sim_substeps = 10;  ///< integration sub-steps per servo period
  bool sim_linear_periods = true;  ///< see machine::SimMachineConfig::linear_periods
  std::uint64_t sim_seed = 1;
  /// [[sim.electrode]]: what the tools really are in the simulation (the controller's tool
  /// table may differ until electrode setting measures them).
  std::vector<machine::SimElectrode> sim_electrodes;

  /// The axis with this letter, or nullptr. Any thread.
  const AxisProfile* find(Axis axis) const noexcept;
  /// The configured axes. Any thread.
  AxisMask axis_mask() const noexcept;
};

/// The simulated machine this profile describes. Non-real-time (copies pitch tables).
machine::SimMachineConfig sim_machine_config(const MachineProfile& profile);

/// How much of an axis' velocity and acceleration its compensation may use at most: the take-up
/// limits plus what the pitch table adds when the axis moves at its limits (slope × velocity;
/// slope × acceleration + the change of slope at a table point × velocity / servo period).
/// Motion is planned within the axis' limits less this, so that the corrected command stays
/// within the limits. Zero without compensation. Any thread.
struct MotionReserve {
  double velocity = 0;
  double acceleration = 0;
};
MotionReserve compensation_reserve(const AxisProfile& axis, double servo_period_s);

}  // namespace opencnc::config
