// SPDX-License-Identifier: GPL-3.0-or-later
// Reading and checking [axis.<letter>] sections: limits, drive, homing, switches, sim model.
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <numbers>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

using machine::JointDrive;

/// Linear and rotary names of the same sim quantity.
struct KindKeys {
  std::string_view linear, rotary;
};
constexpr std::array<KindKeys, 6> kKindKeys{{
    {"mass_kg", "inertia_kg_m2"},
    {"peak_force_n", "peak_torque_nm"},
    {"coulomb_friction_n", "coulomb_friction_nm"},
    {"static_friction_n", "static_friction_nm"},
    {"viscous_friction_n_per_mm_s", "viscous_friction_nm_per_deg_s"},
    {"friction_compensation_n", "friction_compensation_nm"},
}};

/// Defaults of a simulated axis: a 100 kg table on a ball screw, or a rotary table whose
/// worm gear makes it stiff and slow.
machine::SimJointModel default_model(bool rotary) {
  machine::SimJointModel m;
  if (rotary) {
    m.inertia = 0.5;
    m.peak_effort = 200;
    m.coulomb_friction = 2;
    m.static_friction = 2.5;
    m.viscous_friction = 0.002;
  }
  return m;
}

/// decel_midpoint: the return velocity (Vm) runs against the search (Vc), in the working feed's
/// direction, and the latch velocity (Vp) the same way; the overrun takes the axis past the dog.
void read_midpoint_homing(Section& h, const AxisProfile& a, HomingProfile& hp) {
  if (!h.has("return_velocity")) {
    h.missing("return_velocity");
  } else if (const auto v = h.number("return_velocity")) {
    hp.return_velocity = *v;
    if (*v == 0 || (hp.search_velocity != 0 && (*v > 0) == (hp.search_velocity > 0))) {
      h.error("return_velocity",
              fmt::format("{} ({}) must run against search_velocity ({}): back in the working direction",
                          h.key_path("return_velocity"), show(*v), show(hp.search_velocity)),
              "config.homing");
    } else if (std::abs(*v) > a.max_velocity) {
      h.error("return_velocity",
              fmt::format("{} ({}) exceeds the axis' max_velocity ({})", h.key_path("return_velocity"),
                          show(*v), show(a.max_velocity)),
              "config.range");
    }
  }
  if (hp.latch_velocity != 0 && hp.return_velocity != 0 &&
      (hp.latch_velocity > 0) != (hp.return_velocity > 0)) {
    h.error("latch_velocity",
            fmt::format("{} ({}) must run the same way as return_velocity ({})", h.key_path("latch_velocity"),
                        show(hp.latch_velocity), show(hp.return_velocity)),
            "config.homing");
  }
  if (!h.has("overrun")) {
    h.missing("overrun");
  } else {
    hp.overrun = h.number_or("overrun", 0, Bound::Positive);
  }
}

void read_homing(Section& axis_section, AxisProfile& a) {
  const toml::table* t = axis_section.subtable("homing");
  if (t == nullptr) return;
  Section h(*t, axis_section.key_path("homing"),
            {"method", "position", "switch_position", "search_velocity", "latch_velocity", "final_velocity",
             "sequence", "return_velocity", "overrun", "return_after_program"},
            axis_section.reporter());
  HomingProfile& hp = a.homing;
  hp.method = h.choice<HomingMethod>("method",
                                     {{"immediate", HomingMethod::Immediate},
                                      {"switch", HomingMethod::Switch},
                                      {"switch_index", HomingMethod::SwitchIndex},
                                      {"index", HomingMethod::Index},
                                      {"decel_home", HomingMethod::DecelHome},
                                      {"decel_midpoint", HomingMethod::DecelMidpoint}},
                                     HomingMethod::Immediate);
  hp.position = h.number_or("position", 0);
  hp.sequence = static_cast<int>(h.integer("sequence", 0, 8).value_or(0));
  hp.return_after_program = h.boolean_or("return_after_program", false);
  if (hp.method != HomingMethod::DecelMidpoint) {
    h.reject("return_velocity", "applies to decel_midpoint homing only");
    h.reject("overrun", "applies to decel_midpoint homing only");
  }
  if (hp.method == HomingMethod::Immediate) {
    for (std::string_view k :
         {"switch_position", "search_velocity", "latch_velocity", "final_velocity", "return_after_program"}) {
      h.reject(k, "does not apply to immediate homing");
    }
    return;
  }
  hp.switch_position = h.number_or("switch_position", hp.position);
  const bool searches = hp.method != HomingMethod::Index;
  if (!searches)
    h.reject("search_velocity", "does not apply to index homing (the axis latches at latch_velocity)");
  // Each velocity: needed or not, not zero where it sets a direction, within the axis' speed.
  auto velocity = [&](std::string_view key, bool needed, bool signed_direction) -> double {
    if (!h.has(key)) {
      if (needed) h.missing(key);
      return 0;
    }
    const auto v = h.number(key, signed_direction ? Bound::Any : Bound::NonNegative);
    if (!v) return 0;
    if (signed_direction && *v == 0)
      h.error(key, fmt::format("{} must not be 0", h.key_path(key)), "config.range");
    if (std::abs(*v) > a.max_velocity) {
      h.error(key,
              fmt::format("{} ({}) exceeds the axis' max_velocity ({})", h.key_path(key), show(*v),
                          show(a.max_velocity)),
              "config.range");
    }
    return *v;
  };
  hp.search_velocity = searches ? velocity("search_velocity", true, true) : 0;
  hp.latch_velocity = velocity("latch_velocity", true, true);
  hp.final_velocity = velocity("final_velocity", false, false);
  if (hp.method == HomingMethod::DecelMidpoint) read_midpoint_homing(h, a, hp);
}

/// `[axis.<letter>.switches.home_sensor]`: the home switch as an analog proximity sensor.
void read_home_sensor(Section& switches, machine::SwitchLayout& s) {
  const toml::table* t = switches.subtable("home_sensor");
  if (t == nullptr) return;
  Section p(*t, switches.key_path("home_sensor"), {"ramp", "threshold", "hysteresis", "noise", "drift_per_k"},
            switches.reporter());
  machine::ProximitySensor& ps = s.home_sensor;
  ps.present = true;
  ps.ramp = p.number_or("ramp", ps.ramp, Bound::Positive);
  ps.threshold = p.number_or("threshold", ps.threshold, Bound::Positive);
  ps.hysteresis = p.number_or("hysteresis", ps.hysteresis, Bound::NonNegative);
  ps.noise = p.number_or("noise", ps.noise, Bound::NonNegative);
  ps.drift_per_k = p.number_or("drift_per_k", ps.drift_per_k);
  if (ps.threshold >= 1 || ps.hysteresis >= ps.threshold) {
    p.error("threshold",
            fmt::format("{}: threshold ({}) must be below 1 and above hysteresis ({})", p.path(),
                        show(ps.threshold), show(ps.hysteresis)),
            "config.range");
  }
  if (ps.noise > 0 && ps.noise >= ps.hysteresis / 2) {
    p.warning("noise",
              fmt::format("{}: noise ({}) of half the hysteresis ({}) or more makes the sensor chatter",
                          p.path(), show(ps.noise), show(ps.hysteresis)),
              "config.switch-chatter");
  }
  if (!s.home.present) {
    p.error("ramp",
            fmt::format("{} describes the home switch: {}.home is missing", p.path(), switches.path()),
            "config.missing-key");
  }
}

/// The seek-limit move's keys: they need a limit switch, an overtravel the seek stops within
/// (braking from seek_velocity after the period that sees the switch, and the jerk filter's delay).
void read_seek(Section& w, AxisProfile& a, double period_s) {
  LimitSeekProfile& k = a.seek;
  k.overtravel = w.number_or("overtravel", 0, Bound::Positive);
  if (!w.has("seek_velocity")) {
    for (std::string_view key : {"seek_latch_velocity", "seek_back_off"})
      w.reject(key, "needs seek_velocity (the axis seeks its limit switches at that speed)");
    return;
  }
  k.velocity = w.number_or("seek_velocity", 0, Bound::Positive);
  k.latch_velocity = w.number_or("seek_latch_velocity", k.velocity / 10, Bound::Positive);
  k.back_off = w.number_or("seek_back_off", 0.5, Bound::Positive);
  if (!a.switches.limit_neg.present && !a.switches.limit_pos.present) {
    w.error("seek_velocity",
            fmt::format("{}: seeking a limit needs a limit switch (limit_min or limit_max)", w.path()),
            "config.missing-key");
  }
  for (std::string_view key : {"seek_velocity", "seek_latch_velocity"}) {
    const double v = key == "seek_velocity" ? k.velocity : k.latch_velocity;
    if (v > a.max_velocity)
      w.error(key,
              fmt::format("{} ({}) exceeds the axis' max_velocity ({})", w.key_path(key), show(v),
                          show(a.max_velocity)),
              "config.range");
  }
  if (k.latch_velocity > k.velocity)
    w.error("seek_latch_velocity",
            fmt::format("{} ({}) must not exceed seek_velocity ({})", w.key_path("seek_latch_velocity"),
                        show(k.latch_velocity), show(k.velocity)),
            "config.range");
  if (!w.has("overtravel")) {
    w.missing("overtravel");
    return;
  }
  const double a_max = a.max_acceleration;
  const double filter_periods = a.max_jerk > 0 ? std::ceil(2 * a_max / (a.max_jerk * period_s)) : 0;
  const double stop =
      k.velocity * k.velocity / (2 * a_max) + k.velocity * period_s * (2 + filter_periods / 2);
  if (stop > k.overtravel) {
    w.error("seek_velocity",
            fmt::format("{}: from seek_velocity ({}) the axis needs {} to stop once the switch trips, more "
                        "than the overtravel ({})",
                        w.path(), show(k.velocity), show(stop), show(k.overtravel)),
            "config.range");
  }
}

void read_switches(Section& axis_section, AxisProfile& a, double period_s) {
  const toml::table* t = axis_section.subtable("switches");
  if (t == nullptr) return;
  Section w(*t, axis_section.key_path("switches"),
            {"limit_min", "limit_max", "home", "decel", "hysteresis", "noise", "home_sensor", "overtravel",
             "seek_velocity", "seek_latch_velocity", "seek_back_off"},
            axis_section.reporter());
  machine::SwitchLayout& s = a.switches;
  if (auto v = w.number("limit_min")) s.limit_neg = {true, -machine::kInf, *v};
  if (auto v = w.number("limit_max")) s.limit_pos = {true, *v, machine::kInf};
  if (auto v = read_window(w, "home")) s.home = *v;
  if (auto v = read_window(w, "decel")) s.decel = *v;
  if (a.wrapped) {  // the cams on a table that turns without end come round every turn
    if (std::isfinite(s.home.from) && std::isfinite(s.home.to)) s.home.period = 360;
    if (std::isfinite(s.decel.from) && std::isfinite(s.decel.to)) s.decel.period = 360;
  }
  read_seek(w, a, period_s);
  s.hysteresis = w.number_or("hysteresis", s.hysteresis, Bound::NonNegative);
  s.noise = w.number_or("noise", s.noise, Bound::NonNegative);
  read_home_sensor(w, s);
  if (s.limit_neg.present && s.limit_pos.present && s.limit_neg.to >= s.limit_pos.from) {
    w.error("limit_min",
            fmt::format("{}: limit_min ({}) must be less than limit_max ({})", w.path(), show(s.limit_neg.to),
                        show(s.limit_pos.from)),
            "config.limits");
  }
  if (s.noise > 0 && s.noise >= s.hysteresis / 2) {
    w.warning("noise",
              fmt::format("{}: noise ({}) of half the hysteresis ({}) or more makes the switches chatter",
                          w.path(), show(s.noise), show(s.hysteresis)),
              "config.switch-chatter");
  }
  if (!a.wrapped && s.limit_neg.present && s.limit_neg.to >= a.min_limit) {
    w.warning("limit_min",
              fmt::format("{}: limit_min ({}) is inside the soft limits [{}, {}]; moves near the end trip it",
                          w.path(), show(s.limit_neg.to), show(a.min_limit), show(a.max_limit)),
              "config.switch-inside-limits");
  }
  if (!a.wrapped && s.limit_pos.present && s.limit_pos.from <= a.max_limit) {
    w.warning("limit_max",
              fmt::format("{}: limit_max ({}) is inside the soft limits [{}, {}]; moves near the end trip it",
                          w.path(), show(s.limit_pos.from), show(a.min_limit), show(a.max_limit)),
              "config.switch-inside-limits");
  }
}

void read_pitch_table(Section& m, machine::SimJointModel& model) {
  const toml::node* n = m.find("pitch_error");
  if (n == nullptr) return;
  const std::string shape =
      fmt::format("{} must be an array of [position, error] pairs", m.key_path("pitch_error"));
  const toml::array* rows = n->as_array();
  if (rows == nullptr) {
    m.error("pitch_error", shape, "config.type");
    return;
  }
  for (const toml::node& row : *rows) {
    const auto point = number_pair(row);
    if (!point || !std::isfinite(point->first) || !std::isfinite(point->second)) {
      m.reporter().error(&row.source(), shape, "config.type");
      return;
    }
    const auto [pos, err] = *point;
    if (!model.pitch_error.empty() && pos <= model.pitch_error.back().position) {
      m.reporter().error(&row.source(),
                         fmt::format("{}: positions must increase ({} follows {})", m.key_path("pitch_error"),
                                     show(pos), show(model.pitch_error.back().position)),
                         "config.range");
      return;
    }
    model.pitch_error.push_back({pos, err});
  }
}

/// Mechanics: the efforts under their linear or rotary names, friction order, drive reach.
void read_mechanics(Section& m, const AxisProfile& a, machine::SimJointModel& model) {
  const std::string axis_name(1, letter(a.axis));
  for (const KindKeys& k : kKindKeys) {
    const std::string_view wrong = a.rotary ? k.linear : k.rotary;
    const std::string_view right = a.rotary ? k.rotary : k.linear;
    m.reject(wrong, fmt::format("applies to {} axes; {} axis {} takes {}", a.rotary ? "linear" : "rotary",
                                a.rotary ? "rotary" : "linear", axis_name, right));
  }
  auto key = [&](std::size_t i) { return a.rotary ? kKindKeys[i].rotary : kKindKeys[i].linear; };
  model.inertia = m.number_or(key(0), model.inertia, Bound::Positive);
  model.peak_effort = m.number_or(key(1), model.peak_effort, Bound::Positive);
  model.coulomb_friction = m.number_or(key(2), model.coulomb_friction, Bound::NonNegative);
  const auto stiction = m.number(key(3), Bound::NonNegative);
  model.static_friction = stiction.value_or(1.25 * model.coulomb_friction);
  model.viscous_friction = m.number_or(key(4), model.viscous_friction, Bound::NonNegative);
  if (model.static_friction < model.coulomb_friction) {
    m.error(key(3),
            fmt::format("{} ({}) must be at least {} ({})", m.key_path(key(3)), show(model.static_friction),
                        key(2), show(model.coulomb_friction)),
            "config.range");
  }
  // Above static friction the compensation alone would move the axis at a start.
  model.friction_compensation = m.number_or(key(5), model.friction_compensation, Bound::NonNegative);
  if (model.friction_compensation > model.static_friction) {
    m.error(
        key(5),
        fmt::format("{} ({}) must not exceed {} ({}): it alone would break the axis away", m.key_path(key(5)),
                    show(model.friction_compensation), key(3), show(model.static_friction)),
        "config.range");
  }
  const double units_per_si = a.rotary ? 180 / std::numbers::pi : 1000;
  const double reach = (model.peak_effort - model.coulomb_friction) / model.inertia * units_per_si;
  if (reach < a.max_acceleration) {
    m.warning(key(1),
              fmt::format(
                  "{}: the drive can accelerate the axis at {:.0f} at most, less than max_acceleration ({})",
                  m.path(), reach, show(a.max_acceleration)),
              "config.drive-too-weak");
  }
  // Top speed: where the peak effort only just overcomes the friction (viscous in the axis' units).
  if (model.viscous_friction > 0) {
    const double top = (model.peak_effort - model.coulomb_friction) / model.viscous_friction;
    if (top < a.max_velocity) {
      m.warning(
          key(4),
          fmt::format("{}: against its friction the drive can move the axis at {:.0f} at most, less than "
                      "max_velocity ({})",
                      m.path(), top, show(a.max_velocity)),
          "config.drive-too-weak");
    }
  }
}

/// Drive loops, with the limits that keep the sampled cascade stable: the velocity loop
/// well inside the sub-step rate, the current loop at least twice as fast as the velocity
/// loop, the position loop at most a quarter of the velocity loop.
void read_drive(Section& m, const AxisProfile& a, double substep_s, machine::SimJointModel& model) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  model.position_gain = m.number_or("position_gain", model.position_gain, Bound::Positive);
  model.position_integral = m.number_or("position_integral", model.position_integral, Bound::NonNegative);
  model.feed_forward = m.number_or("feed_forward", model.feed_forward, Bound::NonNegative);
  model.velocity_bandwidth_hz =
      m.number_or("velocity_bandwidth_hz", model.velocity_bandwidth_hz, Bound::Positive);
  model.velocity_integral_hz =
      m.number_or("velocity_integral_hz", model.velocity_integral_hz, Bound::NonNegative);
  model.current_bandwidth_hz =
      m.number_or("current_bandwidth_hz", model.current_bandwidth_hz, Bound::NonNegative);
  model.velocity_limit = m.number_or("velocity_limit", model.velocity_limit, Bound::NonNegative);
  model.acceleration_feed_forward =
      m.number_or("acceleration_feed_forward", model.acceleration_feed_forward, Bound::NonNegative);
  if (model.acceleration_feed_forward > 1.5) {
    m.error("acceleration_feed_forward",
            fmt::format("{} must be between 0 and 1.5 (it is {})", m.key_path("acceleration_feed_forward"),
                        show(model.acceleration_feed_forward)),
            "config.range");
  }
  if (model.feed_forward > 1.5) {
    m.error("feed_forward",
            fmt::format("{} must be between 0 and 1.5 (it is {})", m.key_path("feed_forward"),
                        show(model.feed_forward)),
            "config.range");
  }
  const double max_velocity_hz = 0.5 / (kTwoPi * substep_s);
  if (model.velocity_bandwidth_hz > max_velocity_hz) {
    m.error("velocity_bandwidth_hz",
            fmt::format("{} ({}) is too high for the sim sub-step of {} s (at most {})",
                        m.key_path("velocity_bandwidth_hz"), show(model.velocity_bandwidth_hz),
                        show(substep_s), show(std::floor(max_velocity_hz))),
            "config.range");
  }
  if (model.current_bandwidth_hz > 0 && model.current_bandwidth_hz < 2 * model.velocity_bandwidth_hz) {
    m.error("current_bandwidth_hz",
            fmt::format("{} ({}) must be at least twice velocity_bandwidth_hz ({})",
                        m.key_path("current_bandwidth_hz"), show(model.current_bandwidth_hz),
                        show(model.velocity_bandwidth_hz)),
            "config.range");
  }
  const double max_kp = kTwoPi * model.velocity_bandwidth_hz / 4;
  if (model.position_gain > max_kp) {
    m.error(
        "position_gain",
        fmt::format("{} ({}) is too high for a {} Hz velocity loop (at most {})", m.key_path("position_gain"),
                    show(model.position_gain), show(model.velocity_bandwidth_hz), show(std::floor(max_kp))),
        "config.range");
  }
  // Both act through the velocity loop's integrator (sim_joint.cpp).
  if ((model.friction_compensation > 0 || model.acceleration_feed_forward > 0) &&
      model.velocity_integral_hz == 0) {
    m.error("velocity_integral_hz",
            fmt::format("{} is 0, but the friction compensation and the acceleration feed-forward act "
                        "through the velocity loop's integrator",
                        m.key_path("velocity_integral_hz")),
            "config.range");
  }
  if (model.velocity_limit > 0 && model.velocity_limit < a.max_velocity) {
    m.warning("velocity_limit",
              fmt::format("{} ({}) is below the axis' max_velocity ({})", m.key_path("velocity_limit"),
                          show(model.velocity_limit), show(a.max_velocity)),
              "config.drive-too-weak");
  }
}

/// A stepper's mass and pull-out curve (optional: without `pullout_force_n` it is ideal). The
/// servo-drive keys do not apply to it.
void read_stepper_mechanics(Section& m, const AxisProfile& a, machine::SimJointModel& model) {
  for (const auto& [name, value] : m.table()) {
    const std::string_view k = name.str();
    const bool stepper_key =
        k == "backlash" || k == "pitch_error" || k == "start_position" || k == "mass_kg" ||
        k == "coulomb_friction_n" || k == "static_friction_n" || k == "viscous_friction_n_per_mm_s" ||
        k == "inertia_kg_m2" || k == "coulomb_friction_nm" || k == "static_friction_nm" ||
        k == "viscous_friction_nm_per_deg_s" || k == "pullout_force_n" || k == "pullout_speed";
    if (!stepper_key) m.reject(k, "applies to servo axes only (a stepper follows its steps)");
  }
  if (a.rotary) m.reject("pullout_force_n", "applies to linear axes (a rotary stepper is ideal for now)");
  if (!m.has("pullout_force_n")) {
    for (std::string_view k : {"mass_kg", "coulomb_friction_n", "static_friction_n",
                               "viscous_friction_n_per_mm_s", "pullout_speed"})
      m.reject(k, "needs pullout_force_n (without it the stepper is ideal)");
    return;
  }
  model.pullout_effort = m.number_or("pullout_force_n", 0, Bound::Positive);
  model.pullout_speed = m.number_or("pullout_speed", 0, Bound::NonNegative);
  model.inertia = m.number_or("mass_kg", model.inertia, Bound::Positive);
  model.coulomb_friction = m.number_or("coulomb_friction_n", model.coulomb_friction, Bound::NonNegative);
  model.static_friction =
      m.number("static_friction_n", Bound::NonNegative).value_or(1.25 * model.coulomb_friction);
  model.viscous_friction =
      m.number_or("viscous_friction_n_per_mm_s", model.viscous_friction, Bound::NonNegative);
  if (model.static_friction < model.coulomb_friction) {
    m.error("static_friction_n",
            fmt::format("{} ({}) must be at least coulomb_friction_n ({})", m.key_path("static_friction_n"),
                        show(model.static_friction), show(model.coulomb_friction)),
            "config.range");
  }
  // At full speed the motor must still give the friction and the acceleration of the profile.
  const double reach = model.pullout_speed > 0 ? 1 - a.max_velocity / model.pullout_speed : 1.0;
  const double need = model.inertia * a.max_acceleration / 1000 + model.coulomb_friction +
                      model.viscous_friction * a.max_velocity;
  if (model.pullout_effort * reach < need) {
    m.warning("pullout_force_n",
              fmt::format("{}: at max_velocity ({}) the motor gives {:.0f} N, less than the {:.0f} N that "
                          "max_acceleration ({}) and friction need: it will stall",
                          m.path(), show(a.max_velocity), model.pullout_effort * std::max(0.0, reach), need,
                          show(a.max_acceleration)),
              "config.drive-too-weak");
  }
}

void read_sim_model(Section& axis_section, AxisProfile& a, double substep_s) {
  a.sim = default_model(a.rotary);
  const toml::table* t = axis_section.subtable("sim");
  if (t == nullptr) return;
  Section m(*t, axis_section.key_path("sim"),
            {"mass_kg",
             "peak_force_n",
             "coulomb_friction_n",
             "static_friction_n",
             "viscous_friction_n_per_mm_s",
             "inertia_kg_m2",
             "peak_torque_nm",
             "coulomb_friction_nm",
             "static_friction_nm",
             "viscous_friction_nm_per_deg_s",
             "friction_compensation_n",
             "friction_compensation_nm",
             "position_gain",
             "position_integral",
             "feed_forward",
             "velocity_bandwidth_hz",
             "velocity_integral_hz",
             "current_bandwidth_hz",
             "velocity_limit",
             "acceleration_feed_forward",
             "backlash",
             "pitch_error",
             "feedback",
             "index_spacing",
             "index_offset",
             "start_position",
             "pullout_force_n",
             "pullout_speed"},
            axis_section.reporter());
  machine::SimJointModel& model = a.sim;
  if (a.drive == JointDrive::Servo) {
    m.reject("pullout_force_n", "applies to stepper axes only");
    m.reject("pullout_speed", "applies to stepper axes only");
    read_mechanics(m, a, model);
    read_drive(m, a, substep_s, model);
    model.feedback = m.choice<machine::FeedbackSource>(
        "feedback", {{"motor", machine::FeedbackSource::Motor}, {"table", machine::FeedbackSource::Table}},
        model.feedback);
    model.index_spacing = m.number_or("index_spacing", model.index_spacing, Bound::NonNegative);
    model.index_offset = m.number_or("index_offset", model.index_offset);
  } else if (a.drive == JointDrive::Stepper) {
    read_stepper_mechanics(m, a, model);
  } else {
    for (const auto& [name, value] : m.table()) {
      if (name.str() != "start_position")
        m.reject(name.str(), "does not apply to a manual axis (a hand moves it)");
    }
  }
  model.start_position = m.number_or("start_position", model.start_position);
  if (a.drive == JointDrive::Manual) return;
  model.backlash = m.number_or("backlash", model.backlash, Bound::NonNegative);
  read_pitch_table(m, model);
}

void read_drive_kind(Section& s, AxisProfile& a) {
  a.drive = s.choice<JointDrive>(
      "drive",
      {{"servo", JointDrive::Servo}, {"stepper", JointDrive::Stepper}, {"manual", JointDrive::Manual}},
      JointDrive::Servo);
  if (a.drive != JointDrive::Stepper) {
    // Servo: the encoder; manual: the scale the hand-fed axis is read with.
    a.counts_per_unit = s.number_or("encoder_counts_per_unit", a.counts_per_unit, Bound::Positive);
    s.reject("steps_per_unit", "applies to stepper axes only");
  } else {
    a.counts_per_unit = s.required_number("steps_per_unit", Bound::Positive);
    s.reject("encoder_counts_per_unit", "applies to servo axes only");
  }
  a.stall_detector = s.boolean_or("stall_detector", false);
  if (a.drive != JointDrive::Stepper) s.reject("stall_detector", "applies to stepper axes only");
  a.hand_tolerance = s.number_or("hand_tolerance", a.hand_tolerance, Bound::Positive);
  if (a.drive != JointDrive::Manual) s.reject("hand_tolerance", "applies to manual axes only");
}

void read_limits(Section& s, AxisProfile& a) {
  if (a.wrapped) {
    s.reject("min_limit", "does not apply to a wrapped axis (it turns without end)");
    s.reject("max_limit", "does not apply to a wrapped axis (it turns without end)");
    return;
  }
  a.min_limit = s.required_number("min_limit");
  a.max_limit = s.required_number("max_limit");
  if (s.has("min_limit") && s.has("max_limit") && a.min_limit >= a.max_limit) {
    s.error("min_limit",
            fmt::format("{}: min_limit ({}) must be less than max_limit ({})", s.path(), show(a.min_limit),
                        show(a.max_limit)),
            "config.limits");
  }
}

/// What homing needs from the switches, the encoder and the limits.
void check_homing(Section& s, const AxisProfile& a) {
  const HomingProfile& h = a.homing;
  const std::string method_key = "homing";
  if (a.drive == JointDrive::Manual && h.method != HomingMethod::Immediate) {
    s.error(method_key,
            fmt::format("{}: a manual axis cannot make homing moves; it homes immediately (its position at "
                        "power-up is homing.position)",
                        s.path()),
            "config.homing");
    return;
  }
  const bool midpoint = h.method == HomingMethod::DecelMidpoint;
  const bool needs_home = h.method == HomingMethod::Switch || h.method == HomingMethod::SwitchIndex ||
                          h.method == HomingMethod::DecelHome || midpoint;
  if (midpoint && a.switches.home.present && !a.switches.home_sensor.present) {
    s.error(method_key,
            fmt::format("{}: decel_midpoint homing interpolates the level of an analog proximity sensor "
                        "({}.switches.home_sensor)",
                        s.path(), s.path()),
            "config.homing");
  }
  if (needs_home && !a.switches.home.present) {
    s.error(method_key, fmt::format("{}: homing needs a home switch ({}.switches.home)", s.path(), s.path()),
            "config.homing");
  }
  if ((h.method == HomingMethod::DecelHome || midpoint) && !a.switches.decel.present) {
    s.error(method_key,
            fmt::format("{}: {} homing needs a deceleration switch ({}.switches.decel)", s.path(),
                        midpoint ? "decel_midpoint" : "decel_home", s.path()),
            "config.homing");
  }
  const bool needs_index = h.method == HomingMethod::Index || h.method == HomingMethod::SwitchIndex;
  if (needs_index && (a.drive != JointDrive::Servo || a.sim.index_spacing <= 0)) {
    s.error(method_key,
            fmt::format("{}: index homing needs a servo axis whose encoder has index marks "
                        "({}.sim.index_spacing)",
                        s.path(), s.path()),
            "config.homing");
  }
  if (!a.wrapped && a.min_limit < a.max_limit && (h.position < a.min_limit || h.position > a.max_limit)) {
    s.error(method_key,
            fmt::format("{}: the home position ({}) is outside the soft limits [{}, {}]", s.path(),
                        show(h.position), show(a.min_limit), show(a.max_limit)),
            "config.homing");
  }
}

/// A double holds integers exactly up to 2^53; keep the counter well inside that over the travel.
/// And a count must be finer than the following error allowed: with counts of a millimetre, the
/// drive's position could never be told within a 0.5 mm limit (the first move would fault).
void check_resolution(Section& s, const AxisProfile& a) {
  const std::string_view resolution_key =
      a.drive == JointDrive::Servo ? "encoder_counts_per_unit" : "steps_per_unit";
  if (s.has(resolution_key) && a.counts_per_unit > 0 && 1 / a.counts_per_unit > a.max_following_error) {
    s.error(resolution_key,
            fmt::format("{} = {} is no plausible value: one count ({} {}) must be finer than "
                        "max_following_error ({} {})",
                        s.key_path(resolution_key), show(a.counts_per_unit), show(1 / a.counts_per_unit),
                        a.rotary ? "deg" : "mm", show(a.max_following_error), a.rotary ? "deg" : "mm"),
            "config.implausible");
    return;
  }
  constexpr double kMaxCounts = 0x1.0p50;
  const double travel = a.wrapped ? 360.0 * 1e6 : std::max(std::abs(a.min_limit), std::abs(a.max_limit));
  if (travel * a.counts_per_unit > kMaxCounts) {
    const std::string_view key = a.drive == JointDrive::Servo ? "encoder_counts_per_unit" : "steps_per_unit";
    s.error(
        key,
        fmt::format("{}: {} counts per unit over {} units exceed the 2^50 counts a position can hold exactly",
                    s.path(), show(a.counts_per_unit), show(travel)),
        "config.range");
  }
}

// The drive's emergency braking: at least the planned acceleration (a stop never brakes softer).
void read_peak_deceleration(Section& s, AxisProfile& a) {
  if (!s.has("peak_deceleration")) return;
  a.peak_deceleration = s.number_or("peak_deceleration", 0, Bound::Positive);
  if (a.peak_deceleration > 0 && a.peak_deceleration < a.max_acceleration) {
    s.error("peak_deceleration",
            fmt::format("{}: peak_deceleration ({}) must be at least max_acceleration ({})", s.path(),
                        show(a.peak_deceleration), show(a.max_acceleration)),
            "config.limits");
  }
}

AxisProfile read_axis(const toml::table& table, const std::string& path, Axis axis, double period_s,
                      double substep_s, Reporter& r) {
  Section s(table, path,
            {"type", "drive", "max_velocity", "max_acceleration", "max_jerk", "min_limit", "max_limit",
             "wrapped", "max_following_error", "encoder_counts_per_unit", "steps_per_unit", "homing",
             "switches", "sim", "compensation", "stall_detector", "hand_tolerance", "peak_deceleration"},
            r);
  AxisProfile a;
  a.axis = axis;
  a.rotary = is_rotary(axis);
  const bool rotary = s.choice<bool>("type", {{"linear", false}, {"rotary", true}}, a.rotary);
  if (rotary != a.rotary) {
    s.error(
        "type",
        fmt::format("{}: {} is a {} axis in RS274/NGC", path, letter(axis), a.rotary ? "rotary" : "linear"),
        "config.range");
  }
  a.wrapped = s.boolean_or("wrapped", false);
  if (a.wrapped && !a.rotary)
    s.error("wrapped", fmt::format("{}: only rotary axes can wrap", path), "config.range");
  a.max_velocity = s.required_number("max_velocity", Bound::Positive);
  a.max_acceleration = s.required_number("max_acceleration", Bound::Positive);
  a.max_jerk = s.number_or("max_jerk", 0, Bound::NonNegative);
  read_peak_deceleration(s, a);
  read_limits(s, a);
  check_plausible(s, a);
  a.max_following_error = s.number_or("max_following_error", a.max_following_error, Bound::Positive);
  read_drive_kind(s, a);
  check_resolution(s, a);
  read_homing(s, a);
  read_switches(s, a, period_s);
  read_sim_model(s, a, substep_s);
  check_homing(s, a);
  if (a.drive == JointDrive::Manual && a.max_jerk > 0)
    s.reject("max_jerk", "does not apply to a manual axis");
  if (a.drive == JointDrive::Manual && a.peak_deceleration > 0)
    s.reject("peak_deceleration", "does not apply to a manual axis");
  return a;
}

}  // namespace

std::optional<Axis> axis_from_letter(std::string_view letter) noexcept {
  if (letter.size() != 1) return std::nullopt;
  const char c = letter[0] >= 'a' && letter[0] <= 'z' ? static_cast<char>(letter[0] - 'a' + 'A') : letter[0];
  const auto pos = kAxisLetters.find(c);
  if (pos == std::string_view::npos) return std::nullopt;
  return static_cast<Axis>(pos);
}

void read_axes(Section& top, MachineProfile& profile) {
  const toml::table* axes = top.subtable("axis");
  if (axes == nullptr) {
    if (!top.has("axis")) top.missing("axis");
    return;
  }
  Reporter& r = top.reporter();
  std::array<const toml::key*, kAxisCount> seen{};
  for (const auto& [key, node] : *axes) {
    const auto axis = axis_from_letter(key.str());
    if (!axis) {
      r.error(&key.source(),
              fmt::format("axis.{}: '{}' is not an axis letter (X Y Z A B C U V W)", key.str(), key.str()),
              "config.axis-letter");
      continue;
    }
    const auto i = static_cast<std::size_t>(index(*axis));
    if (seen[i] != nullptr) {
      // Keep the definition that comes first in the file; report the later one.
      const toml::key* later = &key;
      if (key.source().begin.line < seen[i]->source().begin.line) std::swap(later, seen[i]);
      r.error(&later->source(),
              fmt::format("axis {} is defined twice: [axis.{}] here and [axis.{}] at line {}", letter(*axis),
                          later->str(), seen[i]->str(), seen[i]->source().begin.line),
              "config.duplicate-axis");
      continue;
    }
    seen[i] = &key;
    if (!node.is_table()) {
      r.error(
          &node.source(),
          fmt::format("axis.{} must be a table ([axis.{}]), not {}", key.str(), key.str(), type_name(node)),
          "config.type");
    }
  }
  const double substep_s = profile.servo_period_s / profile.sim_substeps;
  for (int i = 0; i < kAxisCount; ++i) {
    const toml::key* key = seen[static_cast<std::size_t>(i)];
    const toml::table* t = key != nullptr ? axes->get(key->str())->as_table() : nullptr;
    if (t == nullptr) continue;
    AxisProfile a = read_axis(*t, "axis." + std::string(key->str()), static_cast<Axis>(i),
                              profile.servo_period_s, substep_s, r);
    a.joint = static_cast<int>(profile.axes.size());
    profile.axes.push_back(std::move(a));
  }
  if (profile.axes.empty() && !r.has_errors())
    top.error("axis", "the profile defines no axis", "config.missing-key");
}

}  // namespace opencnc::config::detail
