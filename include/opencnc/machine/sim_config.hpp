// SPDX-License-Identifier: GPL-3.0-or-later
// Parameters of the simulated machine: plain structs the profile loader fills (non-real-time).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "opencnc/core/vec3.hpp"
#include "opencnc/machine/edm.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/plasma.hpp"

namespace opencnc::machine {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// A switch that is active while the table position is inside [from, to] (either end may be
/// infinite, e.g. a limit switch is [-inf, p] or [p, inf]).
struct SwitchWindow {
  bool present = false;
  double from = -kInf;
  double to = kInf;
  /// A wrapped rotary axis' cam comes round every turn: the window repeats every `period` units
  /// (360 degrees; 0 = once).
  double period = 0;
};

/// An inductive proximity sensor with an analog output (the home sensor of decel_midpoint
/// homing). Its level is 0 far from the target and 1 over it, rising over `ramp` units at each end
/// of the on-zone; the zone's window (SwitchWindow::from, to) is where the level crosses
/// `threshold` at the reference temperature (20 °C). Each sample adds a fresh uniform value in
/// ±`noise` (level units). The sensing distance grows with temperature, which widens the on-zone
/// by `drift_per_k` units per kelvin above 20 °C at each end (narrows it below), so its middle
/// stays put while each edge moves. The digital output is a comparator: on at `threshold`, off
/// below `threshold − hysteresis`.
struct ProximitySensor {
  bool present = false;
  double ramp = 0.5;         ///< units from level 0 to level 1 at each end
  double threshold = 0.5;    ///< level at which the output switches on
  double hysteresis = 0.05;  ///< the output switches off below threshold − hysteresis
  double noise = 0.002;      ///< ± level units, uniform, per sample
  double drift_per_k = 0;    ///< outward shift of each edge, units per kelvin above 20 °C
};

/// Temperature at which a proximity sensor's on-zone is exactly its window.
inline constexpr double kReferenceTemperatureC = 20.0;

/// The switches of one joint, at table positions (mm or degrees).
struct SwitchLayout {
  SwitchWindow limit_neg, limit_pos, home, decel;
  /// When present the home switch is this analog sensor over the `home` window (else an ideal
  /// contact with the hysteresis and noise below).
  ProximitySensor home_sensor;
  /// Differential travel: once active, a switch releases only this far outside its window.
  double hysteresis = 0.01;
  /// Each sample moves the switching points by a uniform random amount in ±noise (seeded).
  double noise = 0.001;
};

/// Where the position the drive closes its loop on (and reports) is measured.
enum class FeedbackSource : std::uint8_t {
  Motor,  ///< rotary encoder on the motor: pitch error and backlash are invisible to it
  Table,  ///< linear scale on the table: sees everything the table does
};

/// A point of a lead-screw pitch error table: at nominal screw position `position` the table
/// is at `position + error`.
struct PitchPoint {
  double position = 0;
  double error = 0;
};

/// Mechanics and drive of one simulated servo joint. Linear joints: kg, N, mm; rotary joints:
/// kg·m², N·m, degrees. (`inertia` and the efforts take the unit of the joint kind.)
struct SimJointModel {
  double inertia = 100;            ///< moving mass kg / inertia kg·m², referred to the table
  double peak_effort = 3000;       ///< drive force/torque limit, N or N·m
  double coulomb_friction = 40;    ///< sliding friction, N or N·m
  double static_friction = 50;     ///< breakaway friction, N or N·m (≥ coulomb)
  double viscous_friction = 0.05;  ///< N per mm/s, or N·m per deg/s
  // Drive: position loop (P or PI + velocity feed-forward) → velocity loop (PI) → current
  // loop (first-order lag) → force with saturation.
  double position_gain = 60;           ///< Kp, 1/s
  double position_integral = 0;        ///< Ki, 1/s² (0 = P position loop)
  double feed_forward = 1;             ///< fraction of velocity_ff added to the velocity reference
  double velocity_bandwidth_hz = 150;  ///< velocity loop crossover
  double velocity_integral_hz = 30;    ///< velocity loop PI corner (0 = P velocity loop)
  double current_bandwidth_hz = 1000;  ///< current (force) loop first-order lag
  double velocity_limit = 0;           ///< drive velocity clamp, units/s (0 = none)
  /// Friction compensation, N or N·m (0 = none): when the drive's velocity reference starts from
  /// rest or reverses (beyond 4 counts' worth) the drive sets its velocity integrator to hold this
  /// much in the new direction (set, not added: a standing torque it holds that way is kept).
  double friction_compensation = 0;
  /// Acceleration (torque) feed-forward, the fraction of inertia × the commanded velocity's change
  /// per period the drive adds to its force command (0 = none, 1 = the whole inertia).
  double acceleration_feed_forward = 0;
  // Transmission and feedback.
  double backlash = 0;                  ///< lost motion between motor and table, units
  std::vector<PitchPoint> pitch_error;  ///< sorted by position; empty = perfect screw
  FeedbackSource feedback = FeedbackSource::Motor;
  double index_spacing = 0;   ///< distance between encoder index marks, units (0 = no index)
  double index_offset = 0;    ///< position of one index mark, units
  double start_position = 0;  ///< motor (and table) position at power-up, units
  // Steppers: with a pull-out effort the motor is a mass that must be dragged by the steps (mass
  // `inertia`, the frictions above, injected loads); a period that asks more effort than the
  // pull-out curve gives stalls it: the rotor drops out of step and coasts while steps go on being
  // emitted (they are lost), and locks on a step again once command and rotor are at rest.
  double pullout_effort = 0;  ///< N or N·m the motor gives at standstill; 0 = an ideal stepper
  double pullout_speed = 0;   ///< units/s at which the pull-out effort has fallen to 0 (0 = flat)
};

struct SimJointConfig {
  JointDrive drive = JointDrive::Servo;
  bool rotary = false;
  /// Servo: encoder counts per unit (quantisation of feedback). Stepper: steps per unit.
  double counts_per_unit = 1000;
  SimJointModel model;
  SwitchLayout switches;
  bool stall_detector = false;  ///< stepper: the drive reports a stall (JointInputs::stall)
};

/// A generic digital input driven by a switch on a joint's table position (e.g. "tool
/// retracted" on a hand-fed quill). The input reads the injected value or the switch.
struct SimInputSwitch {
  int channel = -1;  ///< digital input channel; -1 = unused
  int joint = -1;
  SwitchWindow window;
  double hysteresis = 0.01;
  double noise = 0.001;
};

/// Most switch-driven digital inputs a simulated machine has.
inline constexpr int kMaxSimInputSwitches = 8;

struct SimSpindleConfig {
  double max_rpm = 0;                 ///< command is clamped to this
  double acceleration_rpm_s = 2000;   ///< ramp limit of the spindle drive
  double encoder_counts_per_rev = 0;  ///< 0 = no encoder
  double at_speed_tolerance = 0.02;   ///< at_speed when |speed − command| ≤ this × command
  bool orient = true;                 ///< the drive can orient (M19); else requests are ignored
  double orient_rpm = 60;             ///< speed limit while orienting
  double orient_tolerance_deg = 0.5;  ///< orient_done within this angle
  // The torque the drive reports: what accelerates the rotor and overcomes the bearings' and seals'
  // friction, plus a load set by a test (SimMachine::set_spindle_load). The speed itself follows
  // the ramp limit: the drive is assumed strong enough for it, as spindle drives are sized.
  double inertia_kgm2 = 0.01;         ///< rotor, holder and tool about the spindle's axis
  double friction_nm = 0.3;           ///< Coulomb friction while turning
  double viscous_nm_per_krpm = 0.05;  ///< viscous friction per 1000 rpm
};

/// Mains, UPS and DC link.
struct SimPowerConfig {
  double dc_link_nominal_v = 560;  ///< DC link with mains on (rectified 400 V three-phase)
  double dc_link_min_v = 400;      ///< drives trip on undervoltage below this
  double dc_link_capacitance_f = 0.002;
  double idle_power_w = 150;  ///< load on the DC link when no axis moves
  bool ups = false;
  double ups_runtime_s = 300;  ///< battery time after mains loss
  /// The UPS feeds the control only (the usual set-up: the drives' link drains from the signal
  /// on); true models a UPS large enough to hold the drives' link too, for its runtime.
  bool ups_holds_dc_link = false;
};

/// A reference sphere the simulated probe input touches instead of a switch: the electrode (or
/// stylus) in the spindle, whose tip is a ball of `SimSphereProbe::set_electrode`'s radius, closes
/// the probe circuit when it meets the sphere (docs/electrode-setting.md). Table positions, mm.
struct SimSphereTarget {
  bool present = false;
  std::array<int, 3> joints{-1, -1, -1};  ///< the joints of X, Y and Z
  Vec3 centre{};
  double radius = 0;
  double hysteresis = 0.0005;  ///< once touching, the contact opens this far off the surface
  double noise = 0.0002;       ///< ± mm, uniform, per sample
  /// The sphere turns with B (joint `b_joint`, −1: it does not) about the line along the unit
  /// vector `b_direction` (Y on a perfect machine) through X, Z `b_axis` at the centre's Y;
  /// `centre` is where it is with B at `b_at_centre_deg`.
  int b_joint = -1;
  std::array<double, 2> b_axis{};
  Vec3 b_direction{0, 1, 0};
  double b_at_centre_deg = 0;
};

/// The probe: a switch on one joint's table position, or a reference sphere.
struct SimProbeConfig {
  int joint = -1;  ///< -1 = no probe switch
  SwitchWindow trip;
  double hysteresis = 0.002;
  double noise = 0.0005;
  SimSphereTarget sphere;  ///< present: the probe touches this sphere (`joint` is then −1)
};

struct SimToolChangerConfig {
  bool present = false;
  double prepare_time_s = 0.5;
  double change_time_s = 2.0;
};

struct SimProcessConfig {
  bool torch = false;
  double arc_delay_s = 0.5;  ///< torch_on to arc_ok
  bool generator = false;
};

/// The bore of a helical broach and its cutter (docs/broaching.md, "The broaching load"). The
/// stroke joint pulls the cutter through the bore between `bore_start` and `bore_end`; the rotary
/// joint turns the workpiece; the radial joint feeds the cutter out, the bore wall being at
/// `surface`. Positions are the joints' own (mm, degrees).
struct SimBroachConfig {
  bool present = false;
  int load_input = 0;  ///< the analog input the load cell is wired to (kN)
  int stroke_joint = -1, rotary_joint = -1, radial_joint = -1;
  double bore_start = 0, bore_end = 0;  ///< stroke positions where there is material
  double surface = 0;                   ///< radial position at which the cutter touches the wall
  double radius_mm = 40;                ///< the bore's radius (the cutter's width in degrees)
  double specific_force_n_mm2 = 2500;   ///< k_c: force per mm² of chip section
  double width_mm = 10;                 ///< the cutting edge's width (the groove's)
  double speed_gain_per_m_min = 0.05;   ///< the force grows by this fraction per m/min of cutting speed
  double min_speed_mm_s = 0.5;          ///< below this the edge rubs but cuts no chip
  double dull_factor = 1;               ///< a sharp cutter 1; a worn one more
  double noise_kn = 0.02;               ///< ± uniform noise of the load cell, kN
  bool load_on_stroke = false;          ///< the force also acts on the stroke joint against its motion
};

/// Tools whose true electrode the simulation knows (more are a configuration error).
inline constexpr int kMaxSimElectrodes = 32;

/// What a tool really is in the simulated machine (`[[sim.electrode]]`), unknown to the
/// controller: the offsets the tool table would hold if it were exact (X, Y, Z: its lowest point
/// at the controlled point − offset, Z its length) and its tip's radius. A tool change mounts it;
/// the spark gap burns and the reference sphere is touched where it really is.
struct SimElectrode {
  std::int32_t tool = 0;
  Vec3 offset{};
  double tip_radius = 0;
};

struct SimMachineConfig {
  double servo_period_s = 0.001;
  int substeps = 10;  ///< integration sub-steps per servo period
  /// Integrate the periods in which a servo drive is linear, and those of a spindle at speed,
  /// at once (docs/machine.md); false: every sub-step one by one, the encoder quantised in the
  /// drive's loop (the reference the fast path is compared with).
  bool linear_periods = true;
  std::uint64_t seed = 1;
  int joint_count = 0;
  std::array<SimJointConfig, kMaxJoints> joints{};
  bool spindle = false;
  SimSpindleConfig spindle_config;
  bool power_monitor = true;
  SimPowerConfig power;
  SimProbeConfig probe;
  SimToolChangerConfig tool_changer;
  SimProcessConfig process;
  SimBroachConfig broach;  ///< a broaching load cell and the bore it measures (present: false)
  SimEdmConfig edm;  ///< the simulated spark gap (present: an EDM machine)
  SimPlasmaConfig plasma;  ///< the simulated plate and arc (present: a plasma table)
  int digital_inputs = 0, digital_outputs = 0;
  int analog_inputs = 0, analog_outputs = 0;
  std::array<double, kAnalogChannels> analog_in{};  ///< the analog inputs' values at power-up
  std::array<SimInputSwitch, kMaxSimInputSwitches> input_switches{};
  bool handwheel = false;     ///< the machine has a manual pulse generator
  double temperature_c = 20;  ///< machine temperature (proximity sensors drift with it)
  /// The tools' true electrodes; a tool not listed is exactly at the controlled point (offsets 0).
  std::array<SimElectrode, kMaxSimElectrodes> electrodes{};
  int electrode_count = 0;
};

}  // namespace opencnc::machine
