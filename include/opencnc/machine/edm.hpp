// SPDX-License-Identifier: GPL-3.0-or-later
// The sinker EDM's machining conditions (the generator's tables) and gap servo settings as
// fixed-size plain data for the tick and the simulated machine (the profile's [edm], docs/edm.md).
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

namespace opencnc::machine {

/// Most machining conditions a profile defines; a program selects one by its number 1 … 99.
inline constexpr int kMaxEdmConditions = 32;
/// The code that selects a condition and switches the generator on (`M180 P<n>`), and the code
/// that switches it off (`M181`): LinuxCNC user M codes (M100–M199 take P and Q).
inline constexpr int kEdmConditionCode = 180;
inline constexpr int kEdmOffCode = 181;

/// Points of the gap servo's path memory (control::PathMemory): with `path_spacing_mm` between
/// them, how far back along the path the electrode can go.
inline constexpr int kEdmPathPoints = 4096;

/// The planar orbit superimposed on the path (around the tool axis).
enum class OrbitKind : std::uint8_t {
  None,
  Circle,  ///< a circle of the radius
  Square,  ///< a square of half-side the radius, edges parallel to the plane's axes
  Star,    ///< eight rays from the centre to the radius and back (the vector orbit)
};

/// Where a jump lifts the electrode.
enum class JumpMode : std::uint8_t {
  Axis,  ///< along the tool axis, away from the work
  Path,  ///< back along the path already machined
};

/// One machining condition: the generator's settings, the gap servo's, the jump's and the orbit's.
struct EdmCondition {
  int number = 0;  ///< 1 … 99; 0 = empty slot
  // Generator.
  double on_time_us = 0;      ///< pulse on-time
  double off_time_us = 0;     ///< pause between pulses
  double peak_current_a = 0;  ///< discharge current
  double voltage_v = 0;       ///< open-circuit voltage
  std::int8_t polarity = 1;   ///< +1: electrode positive, −1: negative
  // Gap servo.
  double servo_reference_v = 0;  ///< the mean gap voltage the servo holds
  double gain_mm_s_per_v = 0;    ///< path speed per volt above (forward) or below (back) the reference
  double max_forward_mm_s = 0;   ///< forward speed limit (an open gap feeds at this)
  double max_retract_mm_s = 0;   ///< backward speed limit (a short backs off at this)
  double filter_s = 0.005;       ///< time constant of the gap voltage's low-pass filter
  double short_timeout_s = 5;    ///< a short that lasts longer stops the machine with a fault
  /// The finishing cycle's time limit (orbit_finish): an orbit that has not reached its size and
  /// turned there this long after the burn's end stops the machine with a fault.
  double finish_timeout_s = 60;
  // Jump (period 0: off).
  double jump_height_mm = 0;   ///< H: how far the electrode lifts
  double jump_period_s = 0;    ///< T_on: machining time between jumps
  double jump_speed_mm_s = 0;  ///< speed of the lift and the return
  JumpMode jump_mode = JumpMode::Axis;
  // Orbit (kind None: off).
  OrbitKind orbit = OrbitKind::None;
  double orbit_radius_mm = 0;  ///< the final size
  double orbit_step_mm = 0;    ///< the radius grows by this per turn (0: the whole radius at once)
  double orbit_period_s = 0;   ///< one turn
  /// The finishing cycle: the burn's end (M181, another M180) waits at the path's end until the
  /// orbit has grown to its radius and turned once there, the gap servo acting along the orbit's
  /// radius meanwhile (the lateral servo). Needs an orbit.
  bool orbit_finish = false;
  /// The lateral servo: the orbit slows as the gap voltage falls below the reference (stops and
  /// draws in on a short), and in the finishing cycle the gap servo drives its radius.
  bool lateral_servo = false;
  // Adaptive control (off: the values above hold): the bounds within which the gap's state moves
  // the servo's reference and gain and the jump's period and height (each min = max: fixed).
  bool adaptive = false;
  double servo_reference_min_v = 0, servo_reference_max_v = 0;
  double gain_min_mm_s_per_v = 0, gain_max_mm_s_per_v = 0;
  double jump_period_min_s = 0, jump_period_max_s = 0;
  double jump_height_min_mm = 0, jump_height_max_mm = 0;
  // What the generator's table says the condition does (the simulated gap burns by them).
  double side_gap_mm = 0;           ///< spark gap at the electrode's sides, per side (0: not given)
  double electrode_wear_ratio = 0;  ///< electrode volume worn per volume of work removed
  // The technology table's figures a condition sequence is chosen by (edm/sequence.hpp; 0: not given).
  double ra_um = 0;            ///< the surface roughness Ra the condition leaves
  double removal_mm3_min = 0;  ///< the maker's removal rate
};

/// The EDM machine as the tick sees it.
struct EdmConfig {
  bool enabled = false;
  std::int8_t tool_axis = 2;           ///< axis index the electrode lies along (Z)
  double lift_direction = 1;           ///< +1: away from the work is + along the tool axis
  std::int8_t orbit_axes[2] = {0, 1};  ///< the orbit's plane (X, Y)
  double path_spacing_mm = 0.002;      ///< spacing of the path memory's points (backing off)
  double short_timeout_s = 5;          ///< [edm] short_timeout_s: the conditions' default
  double finish_timeout_s = 60;        ///< [edm] finish_timeout_s: the conditions' default
  /// [edm] current_density_max_a_mm2: the most peak current per mm² of frontal area the
  /// electrode takes (a condition sequence's roughing is chosen within it; 0: not given).
  double current_density_max_a_mm2 = 0;
  std::array<EdmCondition, kMaxEdmConditions> conditions{};
  int condition_count = 0;

  /// The condition numbered `number`, or nullptr. Any thread; real-time safe.
  const EdmCondition* find(int number) const noexcept {
    for (int i = 0; i < condition_count; ++i)
      if (conditions[static_cast<std::size_t>(i)].number == number)
        return &conditions[static_cast<std::size_t>(i)];
    return nullptr;
  }
};

static_assert(std::is_trivially_copyable_v<EdmConfig>);

/// What the simulated gap takes from a machining condition (selected by its number).
struct SimEdmConditionEffect {
  int number = 0;                   ///< the condition's number; 0 = empty slot
  double side_gap_mm = 0;           ///< the side spark gap (0: the clean breakdown gap at its voltage)
  double electrode_wear_ratio = 0;  ///< electrode volume worn per volume of work removed
  /// The servo reference the table's side gap was measured at (0: the side gap is the widest
  /// side distance that sparks). With a removal rate of the side walls ([edm.sim] side_walls =
  /// "removal") the sides spark out to the side gap where the mean voltage is this reference.
  double servo_reference_v = 0;
};

/// How the simulated side walls burn.
enum class SideWalls : std::uint8_t {
  Envelope,  ///< at once out to the side gap beyond the swept electrode (no removal rate)
  Removal,   ///< by the side discharges: volume over the side's area, loading the gap voltage
};

/// The simulated EDM process (machine/sim_edm_process.hpp): the front along the tool axis, the
/// cavity's side walls across it, the electrode's wear.
struct SimEdmConfig {
  bool present = false;
  std::int8_t joint = 2;               ///< the joint that feeds the electrode (the tool axis)
  /// Which of the electrode's offsets (0 X, 1 Y, 2 Z; −1 none) lies along the feed joint and along
  /// each lateral joint: the true electrode's tip stands that far from the joints' positions.
  std::int8_t offset_axis = 2;
  std::int8_t lateral_offset_axes[2] = {-1, -1};
  double work_direction = -1;          ///< the work lies this way from the electrode along the joint
  double surface_mm = 0;               ///< the work's surface, joint coordinates (each orientation's start)
  double electrode_area_mm2 = 20;      ///< frontal area: removed volume / area = depth
  double removal_mm3_per_a_us = 5e-8;  ///< volume per discharge per (peak current × on-time)
  double breakdown_um_per_v = 0.3;     ///< the widest gap that sparks, per volt of open voltage
  double discharge_voltage_v = 25;     ///< the burning voltage of a discharge (and of an arc)
  double debris_per_mm3 = 4;           ///< debris concentration added per mm³ removed (0 … 1 scale)
  double flush_time_s = 1.5;           ///< the dielectric's own flushing: debris decays with it
  double jump_flush_time_s = 0.02;     ///< … and with this while the electrode is lifted clear
  double arc_threshold = 0.35;         ///< debris concentration above which discharges turn to arcs
  double noise_v = 1.5;                ///< standard deviation of the measured mean gap voltage
  double short_bridge_mm = 0.02;       ///< an injected short holds until the gap opened this much
  /// Joints whose position tells the work's orientation (B, C: −1 = none): each orientation
  /// (rounded to whole degrees) has its own surface, so two approaches burn two fronts.
  std::int8_t orientation_joints[2] = {-1, -1};
  /// The joints across the tool axis (the orbit's plane: X, Y; −1 = none): the electrode's
  /// lateral position, which burns the cavity's side walls out to the side gap.
  std::int8_t lateral_joints[2] = {-1, -1};
  SideWalls side_walls = SideWalls::Envelope;
  double electrode_perimeter_mm = 20;  ///< the electrode's outline: a side's area is its share × the depth
  /// Debris concentration above which a period's discharges may bridge into a short (0: never);
  /// the probability grows with the debris as the arcs' does above arc_threshold.
  double short_debris = 0;
  std::array<SimEdmConditionEffect, kMaxEdmConditions> conditions{};  ///< from the profile's conditions
  int condition_count = 0;
};

}  // namespace opencnc::machine
