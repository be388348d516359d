// SPDX-License-Identifier: GPL-3.0-or-later
// ServoConfig — everything the servo tick needs to know about the machine, as fixed-size plain
// data (built from a machine profile by the non-real-time side, see controller/servo_setup.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

#include "opencnc/control/load_guard.hpp"
#include "opencnc/machine/edm.hpp"
#include "opencnc/machine/interlocks.hpp"
#include "opencnc/machine/machine_io.hpp"
#include "opencnc/machine/plasma.hpp"
#include "opencnc/machine/process_alarms.hpp"
#include "opencnc/motion/compensation.hpp"
#include "opencnc/motion/coupling.hpp"
#include "opencnc/traj/interpolator.hpp"

namespace opencnc::control {

/// How a joint finds its home (the profile's homing methods, docs/machine.md).
enum class HomeMethod : std::uint8_t {
  Immediate,    ///< no motion: the present position becomes `position` (done at start-up too)
  Switch,       ///< search the home switch, then latch one of its edges at latch velocity
  SwitchIndex,  ///< as Switch, then latch the next encoder index mark
  Index,        ///< latch the next encoder index mark at latch velocity
  DecelHome,    ///< fast to the deceleration dog, then slowly to the home switch
  /// Fast to the dog, a set distance past it, back in the working direction: the middle of the
  /// proximity sensor's on-zone, both edges interpolated between periods (JointHoming).
  DecelMidpoint,
};

struct HomeConfig {
  HomeMethod method = HomeMethod::Immediate;
  double position = 0;         ///< machine position once homed
  double switch_position = 0;  ///< machine position of the latched edge or index mark
  double search_velocity = 0;  ///< units/s, signed: direction of the search
  double latch_velocity = 0;   ///< units/s, signed: direction of the latch move
  double final_velocity = 0;   ///< units/s to `position` (> 0; servo_config() puts max_velocity for 0)
  int sequence = 0;            ///< lower sequences home first; equal ones together
  // DecelMidpoint.
  double return_velocity = 0;         ///< Vm, signed (the working feed's direction)
  double overrun = 0;                 ///< units past the dog's edge before reversing
  double level_on = 0.5;              ///< the sensor's level at which it switches on …
  double level_off = 0.45;            ///< … and off (its comparator, from the profile)
  bool return_after_program = false;  ///< home again when an Auto program ends (M2/M30)
};

/// The seek-limit move of a joint (LimitSeek; the profile's seek keys). velocity 0: no seek.
struct LimitSeekConfig {
  double velocity = 0;        ///< units/s, toward the switch
  double latch_velocity = 0;  ///< units/s: off the switch and onto it again, the trip reported
  double back_off = 0;        ///< units beyond where the switch released
  double overtravel = 0;      ///< units past the trip point before the hard stop
};

/// One joint. The machine layer numbers joints in axis order, one joint per axis.
struct JointConfig {
  std::int8_t axis = 0;  ///< Axis index (X = 0 … W = 8) this joint moves
  bool rotary = false;
  bool wrapped = false;  ///< rotary without end: no soft limits
  machine::JointDrive drive = machine::JointDrive::Servo;
  double counts_per_unit = 1000;  ///< encoder counts (servo) or steps (stepper) per unit
  double max_velocity = 0;        ///< units/s
  double max_acceleration = 0;    ///< units/s²
  double max_jerk = 0;            ///< units/s³, 0 = none
  /// Units/s² the path may brake the joint at in a power-fail stop short of energy (the profile's
  /// peak_deceleration less the compensation's reserve; ≤ max_acceleration: no harder than planned).
  double peak_deceleration = 0;
  double min_limit = 0;           ///< soft limits, machine coordinates
  double max_limit = 0;
  double max_following_error = 1;  ///< units
  HomeConfig home;
  LimitSeekConfig seek;
  double hand_tolerance = 0.05;  ///< manual joints: how close the operator must come, units
};

/// The drives' DC link as the profile's `[power]` states it: the power-fail stop computes the
/// energy left in it from the voltage the drives report (capacitance 0: not stated, never shortened).
struct PowerStopConfig {
  double dc_link_capacitance_f = 0;
  double dc_link_min_v = 0;         ///< the drives trip on undervoltage below this
  double dc_link_idle_power_w = 0;  ///< the link's standing load while the axes stop
};

/// Most step sizes the handwheel offers.
inline constexpr int kMaxHandwheelSteps = 8;

/// The machine as the tick sees it.
struct ServoConfig {
  double period_s = 1e-3;
  int joint_count = 0;
  std::array<JointConfig, machine::kMaxJoints> joints{};
  traj::InterpolatorConfig interpolator;  ///< must match the planner (Planner::interpolator_config)
  double max_spindle_override = 2.0;
  double spindle_max_rpm = 0;
  /// Auto and MDI need every joint homed (true when some joint homes by a method that moves).
  bool homing_required = false;
  /// Pitch-error and backlash compensation per joint (the compensation stage).
  motion::CompensationConfig compensation;
  /// The slave axis a program may couple to its master, and the profile's tables (coupling stage).
  motion::CouplingConfig coupling;
  /// The DC link a power-fail stop must finish on (the stop's deceleration scale).
  PowerStopConfig power_stop;
  /// The process load's thresholds (the load guard stage, after the interlocks).
  LoadGuardConfig load_guard;
  /// Sinker EDM: the machining conditions and the gap servo (the gap servo stage).
  machine::EdmConfig edm;
  /// Plasma: the torch's sequence per cut and its height control (the torch stage).
  machine::PlasmaConfig plasma;
  /// The PLC's interlock rules (evaluated every period after safety).
  machine::InterlockRules interlocks;
  /// The process-input alarms (analog inputs out of range: message, feed hold, or stop and fault).
  machine::ProcessAlarms alarms;
  /// Units per count the operator may select for the handwheel (none: any positive step).
  std::array<double, kMaxHandwheelSteps> handwheel_steps{};
  int handwheel_step_count = 0;
};

static_assert(std::is_trivially_copyable_v<ServoConfig>);

}  // namespace opencnc::control
