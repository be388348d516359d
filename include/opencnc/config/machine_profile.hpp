// SPDX-License-Identifier: GPL-3.0-or-later
// MachineProfile: the validated description of a machine, as plain structs (no TOML types).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "opencnc/core/axes.hpp"
#include "opencnc/core/axis_map.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/sim_config.hpp"

namespace opencnc::config {

enum class HomingMethod : std::uint8_t {
  Immediate,    ///< no motion: the present position becomes `position`
  Switch,       ///< search the home switch, back off, approach it slowly, latch its edge
  SwitchIndex,  ///< as Switch, then latch the next encoder index mark
  Index,        ///< latch the next encoder index mark (no switch)
  DecelHome,    ///< fast to the deceleration dog, slow on it until the home (proximity) switch
};

struct HomingProfile {
  HomingMethod method = HomingMethod::Immediate;
  double position = 0;         ///< machine position of the axis once homed
  double switch_position = 0;  ///< machine position of the latched switch edge or index mark
  double search_velocity = 0;  ///< units/s; the sign is the direction of the search
  double latch_velocity = 0;   ///< units/s; the sign is the direction of the latch move
  double final_velocity = 0;   ///< units/s for the move to `position` (0 = max_velocity)
  int sequence = 0;            ///< lower sequences home first; equal ones together
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
  double min_limit = 0;         ///< soft limits, machine coordinates
  double max_limit = 0;
  double max_following_error = 1;  ///< units; more is a fault
  machine::JointDrive drive = machine::JointDrive::Servo;
  double counts_per_unit = 1000;  ///< encoder counts (servo) or steps (stepper) per unit
  HomingProfile homing;
  machine::SwitchLayout switches;  ///< which switches exist, and where (the sim uses where)
  machine::SimJointModel sim;      ///< mechanics and drive of the simulated axis
};

struct SpindleProfile {
  bool present = false;
  double min_rpm = 0;
  double max_rpm = 0;
  machine::SimSpindleConfig sim;  ///< max_rpm, encoder and orient copied in; the rest sim-only
};

struct PowerProfile {
  bool monitor = false;         ///< the machine reports mains, UPS and DC link
  machine::SimPowerConfig sim;  ///< ups, voltages, and the simulated supply
};

struct ProbeProfile {
  bool present = false;
  int sim_joint = -1;  ///< joint whose table position trips the simulated probe
  machine::SwitchWindow sim_trip;
  double sim_hysteresis = 0.002;
  double sim_noise = 0.0005;
};

/// Generic I/O channel counts (M62–M68, M66). Channels 0 … n-1 exist.
struct IoProfile {
  int digital_inputs = 4, digital_outputs = 4;
  int analog_inputs = 4, analog_outputs = 4;
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
};

struct PlannerOptions {
  int lookahead = 200;              ///< moves in the look-ahead window
  double default_tolerance = 0.01;  ///< mm: path tolerance while a program sets no G64 P
};

struct MachineProfile {
  std::string name;
  std::string description;
  std::string source;  ///< file the profile was read from
  double servo_period_s = 0.001;
  std::vector<AxisProfile> axes;  ///< in joint order
  SpindleProfile spindle;
  PowerProfile power;
  ProbeProfile probe;
  bool tool_changer = false;
  machine::SimToolChangerConfig tool_changer_sim;
  machine::SimProcessConfig process;  ///< torch / generator flags and their simulation
  IoProfile io;
  InterpreterOptions interpreter;
  PlannerOptions planner;
  int sim_substeps = 10;  ///< integration sub-steps per servo period
  bool sim_linear_periods = true;  ///< see machine::SimMachineConfig::linear_periods
  std::uint64_t sim_seed = 1;

  /// The axis with this letter, or nullptr. Any thread.
  const AxisProfile* find(Axis axis) const noexcept;
  /// The configured axes. Any thread.
  AxisMask axis_mask() const noexcept;
};

/// The simulated machine this profile describes. Non-real-time (copies pitch tables).
machine::SimMachineConfig sim_machine_config(const MachineProfile& profile);

}  // namespace opencnc::config
