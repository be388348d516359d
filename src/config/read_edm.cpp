// SPDX-License-Identifier: GPL-3.0-or-later
// [edm]: the sinker EDM's tool axis and orbit plane, its machining conditions ([[edm.condition]],
// selected by number from programs with M180 P<n>) and its simulated spark gap ([edm.sim]).
#include <fmt/format.h>

#include <cmath>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

using machine::EdmCondition;

std::optional<Axis> axis_key(Section& s, std::string_view key, const MachineProfile& p, bool rotary) {
  const auto word = s.string(key);
  if (!word) return std::nullopt;
  const auto axis = axis_from_letter(*word);
  const AxisProfile* a = axis ? p.find(*axis) : nullptr;
  if (a == nullptr || a->rotary != rotary || a->manual()) {
    s.error(key,
            fmt::format("{} must name a driven {} axis of this machine (it is \"{}\")", s.key_path(key),
                        rotary ? "rotary" : "linear", *word),
            "config.range");
    return std::nullopt;
  }
  return axis;
}

// The axes the servo, the jump and the orbit move: a linear tool axis and two linear orbit axes
// across it.
void read_axes_of(Section& s, MachineProfile& p) {
  machine::EdmConfig& c = p.edm.config;
  if (const auto a = axis_key(s, "tool_axis", p, false)) c.tool_axis = static_cast<std::int8_t>(index(*a));
  c.lift_direction = s.choice<double>("lift", {{"+", 1.0}, {"-", -1.0}}, 1.0);
  const auto plane = s.string("orbit_plane");
  if (plane) {
    const auto u = plane->size() == 2 ? axis_from_letter(plane->substr(0, 1)) : std::nullopt;
    const auto v = plane->size() == 2 ? axis_from_letter(plane->substr(1, 1)) : std::nullopt;
    const bool ok = u && v && *u != *v && p.find(*u) && p.find(*v) && !p.find(*u)->rotary &&
                    !p.find(*v)->rotary && index(*u) != c.tool_axis && index(*v) != c.tool_axis;
    if (!ok) {
      s.error("orbit_plane",
              fmt::format("edm.orbit_plane must be two linear axes of this machine across the tool axis, "
                          "such as \"XY\" (it is \"{}\")",
                          *plane),
              "config.range");
    } else {
      c.orbit_axes[0] = static_cast<std::int8_t>(index(*u));
      c.orbit_axes[1] = static_cast<std::int8_t>(index(*v));
    }
  }
  c.path_spacing_mm = s.number_or("path_spacing_mm", c.path_spacing_mm, Bound::Positive);
  c.short_timeout_s = s.number_or("short_timeout_s", c.short_timeout_s, Bound::Positive);
  c.finish_timeout_s = s.number_or("finish_timeout_s", c.finish_timeout_s, Bound::Positive);
  c.current_density_max_a_mm2 = s.number_or("current_density_max_a_mm2", 0, Bound::Positive);
}

double speed_limit(const MachineProfile& p, int axis) {
  const AxisProfile* a = p.find(static_cast<Axis>(axis));
  return a != nullptr ? a->max_velocity : 0.0;
}

void read_generator(Section& t, EdmCondition& c) {
  c.on_time_us = t.required_number("on_time_us", Bound::Positive);
  c.off_time_us = t.required_number("off_time_us", Bound::NonNegative);
  c.peak_current_a = t.required_number("peak_current_a", Bound::Positive);
  c.voltage_v = t.required_number("voltage_v", Bound::Positive);
  c.polarity = t.choice<std::int8_t>("polarity", {{"+", std::int8_t{1}}, {"-", std::int8_t{-1}}}, 1);
}

void read_servo(Section& t, EdmCondition& c, const MachineProfile& p) {
  c.servo_reference_v = t.required_number("servo_reference_v", Bound::Positive);
  if (c.voltage_v > 0 && c.servo_reference_v >= c.voltage_v)
    t.error("servo_reference_v",
            fmt::format("{} must be below voltage_v ({} V): the gap never burns at its open voltage",
                        t.key_path("servo_reference_v"), show(c.voltage_v)),
            "config.range");
  c.gain_mm_s_per_v = t.required_number("gain_mm_s_per_v", Bound::Positive);
  c.max_forward_mm_s = t.required_number("max_forward_mm_s", Bound::Positive);
  c.max_retract_mm_s = t.required_number("max_retract_mm_s", Bound::Positive);
  c.filter_s = t.number_or("filter_s", c.filter_s, Bound::NonNegative);
  c.short_timeout_s = t.number_or("short_timeout_s", p.edm.config.short_timeout_s, Bound::Positive);
  const double v_max = speed_limit(p, p.edm.config.tool_axis);
  for (const char* key : {"max_forward_mm_s", "max_retract_mm_s"}) {
    const double v = std::string_view(key) == "max_forward_mm_s" ? c.max_forward_mm_s : c.max_retract_mm_s;
    if (v_max > 0 && v > v_max)
      t.error(key,
              fmt::format("{} must not exceed the tool axis' max_velocity ({} mm/s)", t.key_path(key),
                          show(v_max)),
              "config.range");
  }
}

void read_jump(Section& t, EdmCondition& c, const MachineProfile& p) {
  c.jump_period_s = t.number_or("jump_period_s", 0, Bound::NonNegative);
  c.jump_height_mm = t.number_or("jump_height_mm", 0, Bound::NonNegative);
  c.jump_speed_mm_s = t.number_or("jump_speed_mm_s", 0, Bound::NonNegative);
  c.jump_mode = t.choice<machine::JumpMode>(
      "jump_mode", {{"axis", machine::JumpMode::Axis}, {"path", machine::JumpMode::Path}},
      machine::JumpMode::Axis);
  if (c.jump_period_s <= 0) return;
  // Reported at the period: the keys that are missing have no place of their own.
  if (c.jump_height_mm <= 0)
    t.error("jump_period_s", "a condition with jump_period_s needs jump_height_mm > 0", "config.range");
  if (c.jump_speed_mm_s <= 0)
    t.error("jump_period_s", "a condition with jump_period_s needs jump_speed_mm_s > 0", "config.range");
  const double v_max = speed_limit(p, p.edm.config.tool_axis);
  if (v_max > 0 && c.jump_speed_mm_s > v_max)
    t.error("jump_speed_mm_s",
            fmt::format("{} must not exceed the tool axis' max_velocity ({} mm/s)",
                        t.key_path("jump_speed_mm_s"), show(v_max)),
            "config.range");
  // A jump back along the path walks the path memory: it must hold the height with room to spare.
  const double memory_mm = 0.5 * machine::kEdmPathPoints * p.edm.config.path_spacing_mm;
  if (c.jump_mode == machine::JumpMode::Path && c.jump_height_mm > memory_mm)
    t.error("jump_height_mm",
            fmt::format("{}: a jump along the path may lift at most {} mm (half the path memory: {} points "
                        "of edm.path_spacing_mm)",
                        t.key_path("jump_height_mm"), show(memory_mm), machine::kEdmPathPoints),
            "config.range");
}

// The fastest a shape moves at its period: a circle 2πr/T; the square's edges and the star's rays,
// run with a smooth start and stop, peak at 1.5 and π/2 times their mean (8r/T and 16r/T).
double orbit_peak_mm_s(const EdmCondition& c) {
  const double r = c.orbit_radius_mm, period = c.orbit_period_s;
  return c.orbit == machine::OrbitKind::Circle   ? 6.283185307179586 * r / period
         : c.orbit == machine::OrbitKind::Square ? 1.5 * 8 * r / period
                                                 : 1.5707963267948966 * 16 * r / period;
}

double orbit_speed_limit(const MachineProfile& p) {
  const machine::EdmConfig& e = p.edm.config;
  return std::min(speed_limit(p, e.orbit_axes[0]), speed_limit(p, e.orbit_axes[1]));
}

void read_orbit(Section& t, EdmCondition& c, const MachineProfile& p) {
  c.orbit = t.choice<machine::OrbitKind>("orbit",
                                         {{"none", machine::OrbitKind::None},
                                          {"circle", machine::OrbitKind::Circle},
                                          {"square", machine::OrbitKind::Square},
                                          {"star", machine::OrbitKind::Star}},
                                         machine::OrbitKind::None);
  c.orbit_radius_mm = t.number_or("orbit_radius_mm", 0, Bound::NonNegative);
  c.orbit_step_mm = t.number_or("orbit_step_mm", 0, Bound::NonNegative);
  c.orbit_period_s = t.number_or("orbit_period_s", 0, Bound::NonNegative);
  if (c.orbit == machine::OrbitKind::None) return;
  if (c.orbit_radius_mm <= 0) t.error("orbit", "an orbit needs orbit_radius_mm > 0", "config.range");
  if (c.orbit_period_s <= 0) t.error("orbit", "an orbit needs orbit_period_s > 0", "config.range");
  if (c.orbit_period_s <= 0) return;
  const double peak = orbit_peak_mm_s(c), v_max = orbit_speed_limit(p);
  if (v_max > 0 && peak > v_max)
    t.error("orbit_period_s",
            fmt::format("{}: the orbit would move at {} mm/s, above the orbit axes' max_velocity ({} mm/s)",
                        t.key_path("orbit_period_s"), show(peak), show(v_max)),
            "config.range");
}

// The finishing cycle needs an orbit to finish. Under the lateral servo its last turn at full size
// runs at twice the period's speed (GapServo::follow_gap): that, too, within the orbit axes' limit.
void read_finish(Section& t, EdmCondition& c, const MachineProfile& p) {
  c.orbit_finish = t.boolean_or("orbit_finish", false);
  c.finish_timeout_s = t.number_or("finish_timeout_s", p.edm.config.finish_timeout_s, Bound::Positive);
  c.lateral_servo = t.boolean_or("lateral_servo", false);
  if (c.orbit_finish && c.orbit == machine::OrbitKind::None)
    t.error("orbit_finish",
            fmt::format("{} needs an orbit (orbit = \"circle\", \"square\" or \"star\")",
                        t.key_path("orbit_finish")),
            "config.range");
  if (!c.orbit_finish || !c.lateral_servo || c.orbit == machine::OrbitKind::None || c.orbit_period_s <= 0)
    return;
  const double peak = orbit_peak_mm_s(c), v_max = orbit_speed_limit(p);
  if (v_max > 0 && peak <= v_max && 2 * peak > v_max)
    t.error("lateral_servo",
            fmt::format("{}: the finishing cycle's last turn runs the orbit at twice its period's speed, {} "
                        "mm/s, above the orbit axes' max_velocity ({} mm/s): a longer orbit_period_s",
                        t.key_path("lateral_servo"), show(2 * peak), show(v_max)),
            "config.range");
}

// Adaptive control's bounds: each setting moves between its min and max (absent: the setting
// itself, so that it stays); the condition's own value must lie within them.
void read_adaptive(Section& t, EdmCondition& c, const MachineProfile& p) {
  c.adaptive = t.boolean_or("adaptive", false);
  struct Bound2 {
    const char* min_key;
    const char* max_key;
    double value;
    double* lo;
    double* hi;
  };
  const Bound2 bounds[] = {
      {"servo_reference_min_v", "servo_reference_max_v", c.servo_reference_v, &c.servo_reference_min_v,
       &c.servo_reference_max_v},
      {"gain_min_mm_s_per_v", "gain_max_mm_s_per_v", c.gain_mm_s_per_v, &c.gain_min_mm_s_per_v,
       &c.gain_max_mm_s_per_v},
      {"jump_period_min_s", "jump_period_max_s", c.jump_period_s, &c.jump_period_min_s, &c.jump_period_max_s},
      {"jump_height_min_mm", "jump_height_max_mm", c.jump_height_mm, &c.jump_height_min_mm,
       &c.jump_height_max_mm},
  };
  for (const Bound2& b : bounds) {
    *b.lo = t.number_or(b.min_key, b.value, Bound::Positive);
    *b.hi = t.number_or(b.max_key, b.value, Bound::Positive);
    if (b.value > 0 && (*b.lo > b.value || *b.hi < b.value))
      t.error(*b.lo > b.value ? b.min_key : b.max_key,
              fmt::format("{} and {} must enclose the condition's own value ({})", t.key_path(b.min_key),
                          t.key_path(b.max_key), show(b.value)),
              "config.range");
  }
  if (c.voltage_v > 0 && c.servo_reference_max_v >= c.voltage_v)
    t.error("servo_reference_max_v",
            fmt::format("{} must be below voltage_v ({} V)", t.key_path("servo_reference_max_v"),
                        show(c.voltage_v)),
            "config.range");
  const double memory_mm = 0.5 * machine::kEdmPathPoints * p.edm.config.path_spacing_mm;
  if (c.jump_mode == machine::JumpMode::Path && c.jump_height_max_mm > memory_mm)
    t.error("jump_height_max_mm",
            fmt::format("{}: a jump along the path may lift at most {} mm", t.key_path("jump_height_max_mm"),
                        show(memory_mm)),
            "config.range");
}

void read_conditions(Section& s, MachineProfile& p) {
  const toml::node* n = s.find("condition");
  const toml::array* list = n != nullptr ? n->as_array() : nullptr;
  if (list == nullptr || !list->is_array_of_tables() || list->empty() ||
      list->size() > static_cast<std::size_t>(machine::kMaxEdmConditions)) {
    s.error("condition",
            fmt::format("edm.condition must be an array of tables ([[edm.condition]]), 1 to {}",
                        machine::kMaxEdmConditions),
            "config.type");
    return;
  }
  machine::EdmConfig& e = p.edm.config;
  for (std::size_t i = 0; i < list->size(); ++i) {
    Section t(*(*list)[i].as_table(), fmt::format("edm.condition[{}]", i + 1),
              {"number",
               "on_time_us",
               "off_time_us",
               "peak_current_a",
               "voltage_v",
               "polarity",
               "servo_reference_v",
               "gain_mm_s_per_v",
               "max_forward_mm_s",
               "max_retract_mm_s",
               "filter_s",
               "jump_height_mm",
               "jump_period_s",
               "jump_speed_mm_s",
               "jump_mode",
               "orbit",
               "orbit_radius_mm",
               "orbit_step_mm",
               "orbit_period_s",
               "short_timeout_s",
               "side_gap_mm",
               "electrode_wear_ratio",
               "orbit_finish",
               "lateral_servo",
               "adaptive",
               "servo_reference_min_v",
               "servo_reference_max_v",
               "gain_min_mm_s_per_v",
               "gain_max_mm_s_per_v",
               "jump_period_min_s",
               "jump_period_max_s",
               "jump_height_min_mm",
               "jump_height_max_mm",
               "finish_timeout_s",
               "ra_um",
               "removal_mm3_min"},
              s.reporter());
    EdmCondition c;
    const auto number = t.integer("number", 1, 99);
    if (!number && !t.has("number")) t.missing("number");
    c.number = static_cast<int>(number.value_or(0));
    if (c.number != 0 && e.find(c.number) != nullptr)
      t.error("number", fmt::format("{}: condition {} is defined twice", t.key_path("number"), c.number),
              "config.range");
    read_generator(t, c);
    read_servo(t, c, p);
    read_jump(t, c, p);
    read_orbit(t, c, p);
    read_finish(t, c, p);
    read_adaptive(t, c, p);
    c.side_gap_mm = t.number_or("side_gap_mm", 0, Bound::NonNegative);
    c.electrode_wear_ratio = t.number_or("electrode_wear_ratio", 0, Bound::NonNegative);
    c.ra_um = t.number_or("ra_um", 0, Bound::Positive);
    c.removal_mm3_min = t.number_or("removal_mm3_min", 0, Bound::Positive);
    if (c.electrode_wear_ratio >= 1)
      t.error("electrode_wear_ratio",
              fmt::format("{} must be below 1 (the electrode would wear faster than the work)",
                          t.key_path("electrode_wear_ratio")),
              "config.range");
    e.conditions[static_cast<std::size_t>(e.condition_count++)] = c;
  }
}

void read_edm_sim(Section& s, MachineProfile& p) {
  const toml::table* st = s.subtable("sim");
  if (st == nullptr) return;
  Section m(
      *st, "edm.sim",
      {"surface_mm", "work", "electrode_area_mm2", "removal_mm3_per_a_us", "breakdown_um_per_v",
       "discharge_voltage_v", "debris_per_mm3", "flush_time_s", "jump_flush_time_s", "arc_threshold",
       "noise_v", "short_bridge_mm", "orientation", "side_walls", "electrode_perimeter_mm", "short_debris"},
      s.reporter());
  machine::SimEdmConfig& c = p.edm.sim;
  c.present = true;
  const AxisProfile* tool = p.find(static_cast<Axis>(p.edm.config.tool_axis));
  c.joint = static_cast<std::int8_t>(tool != nullptr ? tool->joint : 0);
  const auto offset_axis = [](const AxisProfile* a) {  // X, Y, Z carry the tool table's offsets
    return static_cast<std::int8_t>(a != nullptr && index(a->axis) < 3 ? index(a->axis) : -1);
  };
  c.offset_axis = offset_axis(tool);
  c.surface_mm = m.number_or("surface_mm", c.surface_mm);
  c.work_direction = m.choice<double>("work", {{"-", -1.0}, {"+", 1.0}}, -p.edm.config.lift_direction);
  c.electrode_area_mm2 = m.number_or("electrode_area_mm2", c.electrode_area_mm2, Bound::Positive);
  c.removal_mm3_per_a_us = m.number_or("removal_mm3_per_a_us", c.removal_mm3_per_a_us, Bound::NonNegative);
  c.breakdown_um_per_v = m.number_or("breakdown_um_per_v", c.breakdown_um_per_v, Bound::Positive);
  c.discharge_voltage_v = m.number_or("discharge_voltage_v", c.discharge_voltage_v, Bound::Positive);
  c.debris_per_mm3 = m.number_or("debris_per_mm3", c.debris_per_mm3, Bound::NonNegative);
  c.flush_time_s = m.number_or("flush_time_s", c.flush_time_s, Bound::Positive);
  c.jump_flush_time_s = m.number_or("jump_flush_time_s", c.jump_flush_time_s, Bound::Positive);
  c.arc_threshold = m.number_or("arc_threshold", c.arc_threshold, Bound::NonNegative);
  if (c.arc_threshold >= 1) m.error("arc_threshold", "edm.sim.arc_threshold must be below 1", "config.range");
  c.noise_v = m.number_or("noise_v", c.noise_v, Bound::NonNegative);
  c.short_bridge_mm = m.number_or("short_bridge_mm", c.short_bridge_mm, Bound::Positive);
  c.side_walls = m.choice<machine::SideWalls>(
      "side_walls", {{"envelope", machine::SideWalls::Envelope}, {"removal", machine::SideWalls::Removal}},
      machine::SideWalls::Envelope);
  c.electrode_perimeter_mm = m.number_or("electrode_perimeter_mm", c.electrode_perimeter_mm, Bound::Positive);
  c.short_debris = m.number_or("short_debris", c.short_debris, Bound::NonNegative);
  const machine::EdmConfig& e = p.edm.config;
  for (int i = 0; i < 2; ++i) {  // the orbit's plane: the electrode's lateral position
    const AxisProfile* a = p.find(static_cast<Axis>(e.orbit_axes[i]));
    c.lateral_joints[i] = static_cast<std::int8_t>(a != nullptr ? a->joint : -1);
    c.lateral_offset_axes[i] = offset_axis(a);
  }
  for (int i = 0; i < e.condition_count; ++i) {
    const EdmCondition& k = e.conditions[static_cast<std::size_t>(i)];
    c.conditions[static_cast<std::size_t>(i)] = {k.number, k.side_gap_mm, k.electrode_wear_ratio,
                                                 k.servo_reference_v};
  }
  c.condition_count = e.condition_count;
  const toml::node* o = m.find("orientation");
  if (o == nullptr) return;
  const toml::array* list = o->as_array();
  if (list == nullptr || list->size() > 2) {
    m.error("orientation",
            "edm.sim.orientation must be a list of up to two rotary axes, such as [\"B\", \"C\"]",
            "config.type");
    return;
  }
  for (std::size_t i = 0; i < list->size(); ++i) {
    const auto* word = (*list)[i].as_string();
    const auto axis = word != nullptr ? axis_from_letter(word->get()) : std::nullopt;
    const AxisProfile* a = axis ? p.find(*axis) : nullptr;
    if (a == nullptr || !a->rotary) {
      m.error("orientation", "edm.sim.orientation must name rotary axes of this machine", "config.range");
      return;
    }
    c.orientation_joints[i] = static_cast<std::int8_t>(a->joint);
  }
}

}  // namespace

void read_edm(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("edm");
  if (t == nullptr) return;
  Section s(*t, "edm",
            {"tool_axis", "lift", "orbit_plane", "path_spacing_mm", "short_timeout_s", "finish_timeout_s",
             "current_density_max_a_mm2", "condition", "sim"},
            top.reporter());
  profile.edm.present = true;
  profile.edm.config.enabled = true;
  if (!s.has("tool_axis")) s.missing("tool_axis");
  read_axes_of(s, profile);
  if (!profile.process.generator)
    s.error("tool_axis", "an [edm] machine needs its generator: [process] generator = true", "config.range");
  read_conditions(s, profile);
  read_edm_sim(s, profile);
}

}  // namespace opencnc::config::detail
