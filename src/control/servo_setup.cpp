// SPDX-License-Identifier: GPL-3.0-or-later
// Profile → the settings of the servo tick: each stage's from its section of the profile, the
// fixed-size plain data the tick (here or in HAL) is handed.
#include "opencnc/control/servo_setup.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "opencnc/machine/sim_machine.hpp"

namespace opencnc::control {

namespace {

HomeMethod home_method(config::HomingMethod m) {
  switch (m) {
    case config::HomingMethod::Immediate:
      return HomeMethod::Immediate;
    case config::HomingMethod::Switch:
      return HomeMethod::Switch;
    case config::HomingMethod::SwitchIndex:
      return HomeMethod::SwitchIndex;
    case config::HomingMethod::Index:
      return HomeMethod::Index;
    case config::HomingMethod::DecelHome:
      return HomeMethod::DecelHome;
    case config::HomingMethod::DecelMidpoint:
      return HomeMethod::DecelMidpoint;
  }
  return HomeMethod::Immediate;
}

static_assert(config::kMaxCompensationPoints == motion::kMaxPitchPoints);

/// The fixed-size compensation of one joint from its profile.
motion::JointCompensation joint_compensation(const config::AxisProfile& a) {
  motion::JointCompensation c;
  const config::CompensationProfile& p = a.compensation;
  if (!p.present) return c;
  c.enabled = true;
  c.backlash = p.backlash;
  c.max_velocity = p.takeup_velocity;
  c.max_acceleration = p.takeup_acceleration;
  const std::size_t n = std::min<std::size_t>(p.positions.size(), motion::kMaxPitchPoints);
  c.pitch.count = static_cast<int>(n);
  for (std::size_t i = 0; i < n; ++i) {
    c.pitch.position[i] = p.positions[i];
    c.pitch.forward[i] = p.forward[i];
    c.pitch.reverse[i] = p.reverse[i];
  }
  return c;
}

}  // namespace

ServoConfig servo_config(const config::MachineProfile& profile,
                         const traj::InterpolatorConfig& interpolator) {
  ServoConfig s{};  // value-initialised: padding zero too (shared_setup compares set-ups byte for byte)
  s.period_s = profile.servo_period_s;
  s.joint_count = static_cast<int>(std::min<std::size_t>(profile.axes.size(), machine::kMaxJoints));
  for (const config::AxisProfile& a : profile.axes) {
    if (a.joint < 0 || a.joint >= machine::kMaxJoints) continue;
    JointConfig& j = s.joints[static_cast<std::size_t>(a.joint)];
    // Jogs and homing move within what the compensation leaves free, as programs do.
    const config::MotionReserve r = config::compensation_reserve(a, profile.servo_period_s);
    j.axis = static_cast<std::int8_t>(index(a.axis));
    j.rotary = a.rotary;
    j.wrapped = a.wrapped;
    j.drive = a.drive;
    j.counts_per_unit = a.counts_per_unit;
    j.max_velocity = a.max_velocity - r.velocity;
    j.max_acceleration = a.max_acceleration - r.acceleration;
    j.max_jerk = a.max_jerk;
    // The compensation may still take its reserve while the path brakes at its peak.
    j.peak_deceleration = std::max(j.max_acceleration, a.peak_deceleration - r.acceleration);
    j.min_limit = a.min_limit;
    j.max_limit = a.max_limit;
    j.max_following_error = a.max_following_error;
    const config::HomingProfile& h = a.homing;
    j.home.method = home_method(h.method);
    j.home.position = h.position;
    j.home.switch_position = h.switch_position;
    j.home.search_velocity = h.search_velocity;
    j.home.latch_velocity = h.latch_velocity;
    j.home.final_velocity =
        std::min(h.final_velocity > 0 ? h.final_velocity : a.max_velocity, j.max_velocity);
    j.home.sequence = h.sequence;
    j.home.return_velocity = h.return_velocity;
    j.home.overrun = h.overrun;
    j.home.level_on = a.switches.home_sensor.threshold;
    j.home.level_off = a.switches.home_sensor.threshold - a.switches.home_sensor.hysteresis;
    j.home.return_after_program = h.return_after_program;
    j.seek = {a.seek.velocity, a.seek.latch_velocity, a.seek.back_off, a.seek.overtravel};
    j.hand_tolerance = a.hand_tolerance;
    if (j.home.method != HomeMethod::Immediate) s.homing_required = true;
    s.compensation.joints[static_cast<std::size_t>(a.joint)] = joint_compensation(a);
  }
  s.compensation.period_s = profile.servo_period_s;
  s.interlocks = profile.interlocks.rules;
  s.alarms = profile.alarms.alarms;
  if (profile.handwheel.present) {
    s.handwheel_step_count =
        static_cast<int>(std::min<std::size_t>(profile.handwheel.steps.size(), kMaxHandwheelSteps));
    for (int k = 0; k < s.handwheel_step_count; ++k)
      s.handwheel_steps[static_cast<std::size_t>(k)] = profile.handwheel.steps[static_cast<std::size_t>(k)];
  }
  // Field by field: the padding after filter_ticks stays the zero shared_setup() compares.
  static_assert(sizeof(traj::InterpolatorConfig) == 40,
                "a field was added to the interpolator's settings: copy it");
  s.interpolator.period_s = interpolator.period_s;
  s.interpolator.filter_ticks = interpolator.filter_ticks;
  s.interpolator.max_feed_override = interpolator.max_feed_override;
  s.interpolator.max_path_accel = interpolator.max_path_accel;
  s.interpolator.max_path_speed = interpolator.max_path_speed;
  s.spindle_max_rpm = profile.spindle.present ? profile.spindle.max_rpm : 0.0;
  s.coupling = coupling_config(profile.coupling);
  s.load_guard = load_guard_config(profile);
  if (profile.power.monitor && profile.power.dc_link_capacitance_f > 0) {
    s.power_stop.dc_link_capacitance_f = profile.power.dc_link_capacitance_f;
    s.power_stop.dc_link_min_v = profile.power.sim.dc_link_min_v;
    s.power_stop.dc_link_idle_power_w = profile.power.dc_link_idle_power_w;
  }
  s.edm = profile.edm.config;
  s.plasma = profile.plasma.config;  // enabled 0 without [process.plasma]: the stage does nothing
  return s;
}

LoadGuardConfig load_guard_config(const config::MachineProfile& profile) {
  const config::BroachingProfile& b = profile.broaching;
  LoadGuardConfig g{};
  if (!b.present) return g;
  g.enabled = true;
  g.input = b.load_input;
  g.hold_kn = b.hold_kn;
  g.retract_kn = b.retract_kn;
  g.confirm_periods = std::max(1, static_cast<int>(std::ceil(b.confirm_s / profile.servo_period_s - 1e-9)));
  g.radial_axis = static_cast<std::int8_t>(index(b.radial));
  g.retract_lift = b.retract_lift;
  g.retract_speed = b.retract_speed;
  return g;
}

namespace {

// The EDM's configuration field by field on zeroed bytes (a flag and small integers before
// doubles leave padding that copies carry along), for shared_setup's byte-for-byte comparison.
// A new field changes these sizes: copy it below too.
static_assert(sizeof(machine::EdmCondition) == 264 && sizeof(machine::EdmConfig) == 56 + 32 * 264 + 8,
              "a field was added to the EDM's configuration: copy it in plain_edm_config");
void plain_edm_config(const machine::EdmConfig& e, machine::EdmConfig& out) {
  std::memset(static_cast<void*>(&out), 0, sizeof out);
  out.enabled = e.enabled;
  out.tool_axis = e.tool_axis;
  out.lift_direction = e.lift_direction;
  out.orbit_axes[0] = e.orbit_axes[0];
  out.orbit_axes[1] = e.orbit_axes[1];
  out.path_spacing_mm = e.path_spacing_mm;
  out.short_timeout_s = e.short_timeout_s;
  out.finish_timeout_s = e.finish_timeout_s;
  out.current_density_max_a_mm2 = e.current_density_max_a_mm2;
  out.condition_count = e.condition_count;
  for (std::size_t i = 0; i < e.conditions.size() && static_cast<int>(i) < e.condition_count; ++i) {
    const machine::EdmCondition& c = e.conditions[i];
    machine::EdmCondition& o = out.conditions[i];
    o.number = c.number;
    o.on_time_us = c.on_time_us;
    o.off_time_us = c.off_time_us;
    o.peak_current_a = c.peak_current_a;
    o.voltage_v = c.voltage_v;
    o.polarity = c.polarity;
    o.servo_reference_v = c.servo_reference_v;
    o.gain_mm_s_per_v = c.gain_mm_s_per_v;
    o.max_forward_mm_s = c.max_forward_mm_s;
    o.max_retract_mm_s = c.max_retract_mm_s;
    o.filter_s = c.filter_s;
    o.short_timeout_s = c.short_timeout_s;
    o.finish_timeout_s = c.finish_timeout_s;
    o.jump_height_mm = c.jump_height_mm;
    o.jump_period_s = c.jump_period_s;
    o.jump_speed_mm_s = c.jump_speed_mm_s;
    o.jump_mode = c.jump_mode;
    o.orbit = c.orbit;
    o.orbit_radius_mm = c.orbit_radius_mm;
    o.orbit_step_mm = c.orbit_step_mm;
    o.orbit_period_s = c.orbit_period_s;
    o.orbit_finish = c.orbit_finish;
    o.adaptive = c.adaptive;
    o.lateral_servo = c.lateral_servo;
    o.servo_reference_min_v = c.servo_reference_min_v;
    o.servo_reference_max_v = c.servo_reference_max_v;
    o.gain_min_mm_s_per_v = c.gain_min_mm_s_per_v;
    o.gain_max_mm_s_per_v = c.gain_max_mm_s_per_v;
    o.jump_period_min_s = c.jump_period_min_s;
    o.jump_period_max_s = c.jump_period_max_s;
    o.jump_height_min_mm = c.jump_height_min_mm;
    o.jump_height_max_mm = c.jump_height_max_mm;
    o.side_gap_mm = c.side_gap_mm;
    o.electrode_wear_ratio = c.electrode_wear_ratio;
    o.ra_um = c.ra_um;
    o.removal_mm3_min = c.removal_mm3_min;
  }
}

}  // namespace

SharedSetup shared_setup(const config::MachineProfile& profile, const ServoConfig& servo) {
  SharedSetup s;
  // Zeroed first, padding included: the tick compares set-ups byte for byte to keep its servo
  // (and the joints' homed state) when a restarted controller hands over the same one.
  std::memset(static_cast<void*>(&s), 0, sizeof s);
  std::memcpy(static_cast<void*>(&s.servo), &servo, sizeof servo);
  // The rules' padding bytes hold whatever their copies left: rebuild them field by field on zeroed
  // bytes, so that the same profile always gives the same bytes.
  machine::InterlockRules& rules = s.servo.interlocks;
  for (std::size_t i = 0; i < rules.rules.size(); ++i) {
    const machine::InterlockRule r = servo.interlocks.rules[i];
    machine::InterlockRule& out = rules.rules[i];
    std::memset(static_cast<void*>(&out), 0, sizeof out);
    if (static_cast<int>(i) >= rules.count) continue;
    out.action = r.action;
    out.token_count = r.token_count;
    for (std::size_t t = 0; t < r.token_count && t < r.tokens.size(); ++t) {
      out.tokens[t].op = r.tokens[t].op;
      out.tokens[t].signal = r.tokens[t].signal;
      out.tokens[t].index = r.tokens[t].index;
    }
  }
  // The process alarms the same way (their structs have padding too).
  machine::ProcessAlarms& alarms = s.servo.alarms;
  std::memset(static_cast<void*>(&alarms), 0, sizeof alarms);
  alarms.count = servo.alarms.count;
  for (std::size_t i = 0; i < alarms.alarms.size() && static_cast<int>(i) < alarms.count; ++i) {
    const machine::ProcessAlarm& a = servo.alarms.alarms[i];
    machine::ProcessAlarm& out = alarms.alarms[i];
    out.channel = a.channel;
    out.has_low = a.has_low;
    out.has_high = a.has_high;
    out.low = a.low;
    out.high = a.high;
    out.hysteresis = a.hysteresis;
    out.reaction = a.reaction;
  }
  // The compensated joints the same way (a flag and a point count before doubles): a re-attaching
  // controller with the same pitch tables hands over the same bytes.
  for (std::size_t j = 0; j < s.servo.compensation.joints.size(); ++j) {
    const motion::JointCompensation& c = servo.compensation.joints[j];
    motion::JointCompensation& out = s.servo.compensation.joints[j];
    std::memset(static_cast<void*>(&out), 0, sizeof out);
    out.enabled = c.enabled;
    out.pitch.count = c.pitch.count;
    out.pitch.position = c.pitch.position;
    out.pitch.forward = c.pitch.forward;
    out.pitch.reverse = c.pitch.reverse;
    out.backlash = c.backlash;
    out.max_velocity = c.max_velocity;
    out.max_acceleration = c.max_acceleration;
  }
  plain_edm_config(servo.edm, s.servo.edm);
  const machine::MachineCapabilities caps =
      machine::SimMachine(config::sim_machine_config(profile)).capabilities();
  std::memcpy(static_cast<void*>(&s.capabilities), &caps, sizeof caps);
  return s;
}

motion::CouplingConfig coupling_config(const config::CouplingProfile& c) {
  motion::CouplingConfig out{};
  out.enabled = c.present;
  out.master_axis = static_cast<std::int8_t>(index(c.master));
  out.slave_axis = static_cast<std::int8_t>(index(c.slave));
  out.source = c.from_actual ? motion::CouplingSource::Actual : motion::CouplingSource::Command;
  out.engage_tolerance_master = c.engage_tolerance_um / 1000;                                        // mm
  out.engage_tolerance_slave = c.engage_tolerance_um / 1000 / c.radius_mm * 180 / std::numbers::pi;  // deg
  out.engage_timeout_s = c.engage_timeout_s;
  const std::size_t n = std::min<std::size_t>(c.tables.size(), motion::kMaxCouplingTables);
  for (std::size_t t = 0; t < n; ++t) {
    const config::CouplingTableProfile& tp = c.tables[t];
    out.table_kind[t] = tp.kind == config::CouplingTableProfile::Kind::Cam ? motion::CouplingKind::Cam
                                                                           : motion::CouplingKind::PitchTable;
    motion::CouplingTable& table = out.tables[t];
    table.count = static_cast<int>(std::min<std::size_t>(tp.points.size(), motion::kMaxCouplingPoints));
    for (int k = 0; k < table.count; ++k) {
      table.master[static_cast<std::size_t>(k)] = tp.points[static_cast<std::size_t>(k)].first;
      table.value[static_cast<std::size_t>(k)] = tp.points[static_cast<std::size_t>(k)].second;
    }
  }
  return out;
}

}  // namespace opencnc::control
