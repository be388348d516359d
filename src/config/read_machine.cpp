// SPDX-License-Identifier: GPL-3.0-or-later
// Reading the machine-wide sections: sim, spindle, power, probe, tool changer, process, I/O,
// interpreter and planner options.
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <system_error>

#include "opencnc/core/atomic_file.hpp"
#include "sections.hpp"

namespace opencnc::config::detail {

std::optional<std::pair<double, double>> number_pair(const toml::node& node) {
  const toml::array* pair = node.as_array();
  if (pair == nullptr || pair->size() != 2) return std::nullopt;
  const std::optional<double> first = (*pair)[0].value<double>();
  const std::optional<double> second = (*pair)[1].value<double>();
  if (!first.has_value() || !second.has_value() || std::isnan(*first) || std::isnan(*second))
    return std::nullopt;
  return std::pair{*first, *second};
}

bool read_triple(Section& s, std::string_view key, Vec3& out, std::string_view unit) {
  const toml::node* n = s.find(key);
  if (n == nullptr) {
    s.missing(key);
    return false;
  }
  const toml::array* a = n->as_array();
  bool ok = a != nullptr && a->size() == 3;
  Vec3 v{};
  for (std::size_t i = 0; ok && i < 3; ++i) {
    const std::optional<double> x = (*a)[i].value<double>();
    ok = x.has_value() && std::isfinite(*x);
    if (ok) v[static_cast<int>(i)] = *x;
  }
  if (!ok) {
    s.error(key,
            fmt::format("{} must be [x, y, z]: three finite numbers{}{}", s.key_path(key),
                        unit.empty() ? "" : ", ", unit),
            "config.type");
    return false;
  }
  out = v;
  return true;
}

std::optional<machine::SwitchWindow> read_window(Section& section, std::string_view key) {
  const toml::node* n = section.find(key);
  if (n == nullptr) return std::nullopt;
  const auto window = number_pair(*n);
  if (!window) {
    section.error(
        key, fmt::format("{} must be [from, to]: two numbers, inf and -inf allowed", section.key_path(key)),
        "config.type");
    return std::nullopt;
  }
  const auto [from, to] = *window;
  if (from > to) {
    section.error(key,
                  fmt::format("{}: from ({}) must not be greater than to ({})", section.key_path(key),
                              show(from), show(to)),
                  "config.range");
    return std::nullopt;
  }
  return machine::SwitchWindow{true, from, to};
}

void read_sim(Section& top, MachineProfile& profile) {
  constexpr double kDefaultSubstep = 1e-4;
  const double period = profile.servo_period_s;
  profile.sim_substeps = std::max(1, static_cast<int>(std::lround(period / kDefaultSubstep)));
  const toml::table* t = top.subtable("sim");
  if (t == nullptr) return;
  Section s(*t, "sim", {"substep_s", "seed", "linear_periods", "temperature_c", "electrode"}, top.reporter());
  read_sim_electrodes(s, profile);
  profile.sim_temperature_c = s.number_or("temperature_c", profile.sim_temperature_c);
  if (const auto h = s.number("substep_s", Bound::Positive)) {
    const double n = period / *h;
    const double whole = std::round(n);
    if (whole < 1 || whole > 1000 || std::abs(n - whole) > 1e-6 * whole) {
      s.error("substep_s",
              fmt::format("sim.substep_s ({}) must divide servo_period_s ({}) into 1 to 1000 equal steps",
                          show(*h), show(period)),
              "config.range");
    } else {
      profile.sim_substeps = static_cast<int>(whole);
    }
  }
  profile.sim_seed =
      static_cast<std::uint64_t>(s.integer("seed", 0, std::numeric_limits<std::int64_t>::max()).value_or(1));
  profile.sim_linear_periods = s.boolean_or("linear_periods", true);
}

void read_spindle(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("spindle");
  if (t == nullptr) return;
  Section s(*t, "spindle",
            {"max_rpm", "min_rpm", "encoder_counts_per_rev", "orient", "rated_torque_nm", "sim"},
            top.reporter());
  SpindleProfile& sp = profile.spindle;
  sp.present = true;
  sp.max_rpm = s.required_number("max_rpm", Bound::Positive);
  // The fastest spindles (dental, PCB drills) turn at a few 100,000 rpm: beyond 1e6 is a typo,
  // and a run would wait for ever for the spindle to reach it.
  constexpr double kMaxPlausibleRpm = 1e6;
  if (sp.max_rpm > kMaxPlausibleRpm) {
    s.error(
        "max_rpm",
        fmt::format("spindle.max_rpm = {} is no plausible value: spindles turn at most {:g} rpm (a typo, or "
                    "another unit?)",
                    show(sp.max_rpm), kMaxPlausibleRpm),
        "config.implausible");
    sp.max_rpm = kMaxPlausibleRpm;
  }
  sp.min_rpm = s.number_or("min_rpm", 0, Bound::NonNegative);
  if (sp.min_rpm > sp.max_rpm) {
    s.error(
        "min_rpm",
        fmt::format("spindle.min_rpm ({}) must not exceed max_rpm ({})", show(sp.min_rpm), show(sp.max_rpm)),
        "config.limits");
  }
  sp.sim.max_rpm = sp.max_rpm;
  sp.sim.encoder_counts_per_rev =
      static_cast<double>(s.integer("encoder_counts_per_rev", 0, 1 << 24).value_or(0));
  sp.sim.orient = s.boolean_or("orient", false);
  sp.rated_torque_nm = s.number_or("rated_torque_nm", 0, Bound::Positive);
  const toml::table* st = s.subtable("sim");
  if (st == nullptr) return;
  Section m(*st, "spindle.sim",
            {"acceleration_rpm_s", "at_speed_tolerance", "orient_rpm", "orient_tolerance_deg", "inertia_kgm2",
             "friction_nm", "viscous_nm_per_krpm"},
            top.reporter());
  sp.sim.acceleration_rpm_s = m.number_or("acceleration_rpm_s", sp.sim.acceleration_rpm_s, Bound::Positive);
  sp.sim.at_speed_tolerance =
      m.number_or("at_speed_tolerance", sp.sim.at_speed_tolerance, Bound::NonNegative);
  sp.sim.orient_rpm = m.number_or("orient_rpm", sp.sim.orient_rpm, Bound::Positive);
  sp.sim.orient_tolerance_deg =
      m.number_or("orient_tolerance_deg", sp.sim.orient_tolerance_deg, Bound::Positive);
  sp.sim.inertia_kgm2 = m.number_or("inertia_kgm2", sp.sim.inertia_kgm2, Bound::NonNegative);
  sp.sim.friction_nm = m.number_or("friction_nm", sp.sim.friction_nm, Bound::NonNegative);
  sp.sim.viscous_nm_per_krpm =
      m.number_or("viscous_nm_per_krpm", sp.sim.viscous_nm_per_krpm, Bound::NonNegative);
}

void read_power(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("power");
  if (t == nullptr) return;
  Section s(*t, "power",
            {"monitor", "ups", "dc_link_nominal_v", "dc_link_min_v", "dc_link_capacitance_f",
             "dc_link_idle_power_w", "sim", "resume_tolerance_mm", "resume_tolerance_deg", "resume_run_in_mm",
             "resume_run_in_speed_mm_min"},
            top.reporter());
  PowerProfile& p = profile.power;
  p.monitor = s.boolean_or("monitor", true);
  p.resume_tolerance_mm = s.number_or("resume_tolerance_mm", p.resume_tolerance_mm, Bound::Positive);
  p.resume_tolerance_deg = s.number_or("resume_tolerance_deg", p.resume_tolerance_deg, Bound::Positive);
  p.resume_run_in_mm = s.number_or("resume_run_in_mm", p.resume_run_in_mm, Bound::NonNegative);
  p.resume_run_in_speed_mm_min =
      s.number_or("resume_run_in_speed_mm_min", p.resume_run_in_speed_mm_min, Bound::Positive);
  p.sim.ups = s.boolean_or("ups", false);
  p.sim.dc_link_nominal_v = s.number_or("dc_link_nominal_v", p.sim.dc_link_nominal_v, Bound::Positive);
  p.sim.dc_link_min_v = s.number_or("dc_link_min_v", p.sim.dc_link_min_v, Bound::Positive);
  if (p.sim.dc_link_min_v >= p.sim.dc_link_nominal_v) {
    s.error("dc_link_min_v",
            fmt::format("power.dc_link_min_v ({}) must be below dc_link_nominal_v ({})",
                        show(p.sim.dc_link_min_v), show(p.sim.dc_link_nominal_v)),
            "config.limits");
  }
  // The link as the machine states it; the simulated link is the same unless [power.sim] says.
  p.dc_link_capacitance_f = s.number_or("dc_link_capacitance_f", 0, Bound::Positive);
  p.dc_link_idle_power_w = s.number_or("dc_link_idle_power_w", 0, Bound::NonNegative);
  if (p.dc_link_capacitance_f > 0) p.sim.dc_link_capacitance_f = p.dc_link_capacitance_f;
  if (s.has("dc_link_idle_power_w")) p.sim.idle_power_w = p.dc_link_idle_power_w;
  if (s.has("dc_link_idle_power_w") && p.dc_link_capacitance_f == 0)
    s.reject("dc_link_idle_power_w", "needs power.dc_link_capacitance_f");
  const toml::table* st = s.subtable("sim");
  if (st == nullptr) return;
  Section m(*st, "power.sim", {"dc_link_capacitance_f", "idle_power_w", "ups_runtime_s", "ups_holds_dc_link"},
            top.reporter());
  p.sim.dc_link_capacitance_f =
      m.number_or("dc_link_capacitance_f", p.sim.dc_link_capacitance_f, Bound::Positive);
  p.sim.idle_power_w = m.number_or("idle_power_w", p.sim.idle_power_w, Bound::NonNegative);
  p.sim.ups_runtime_s = m.number_or("ups_runtime_s", p.sim.ups_runtime_s, Bound::NonNegative);
  if (!p.sim.ups) m.reject("ups_runtime_s", "needs power.ups = true");
  p.sim.ups_holds_dc_link = m.boolean_or("ups_holds_dc_link", false);
  if (!p.sim.ups) m.reject("ups_holds_dc_link", "needs power.ups = true");
}

void read_probe(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("probe");
  if (t == nullptr) return;
  Section s(*t, "probe", {"sim", "reference_sphere"}, top.reporter());
  ProbeProfile& p = profile.probe;
  p.present = true;
  read_reference_sphere(s, profile);
  const toml::table* st = s.subtable("sim");
  if (st == nullptr) return;
  if (p.reference_sphere.sim)
    s.error("sim",
            "[probe.sim] and [probe.reference_sphere.sim] exclude each other: the simulated probe is one or "
            "the other",
            "config.range");
  Section m(*st, "probe.sim", {"axis", "trip", "hysteresis", "noise"}, top.reporter());
  if (const auto name = m.string("axis")) {
    const auto axis = axis_from_letter(*name);
    const AxisProfile* a = axis ? profile.find(*axis) : nullptr;
    if (a == nullptr) {
      m.error("axis", fmt::format("probe.sim.axis (\"{}\") is not an axis of this profile", *name),
              "config.range");
    } else {
      p.sim_joint = a->joint;
    }
  } else if (!m.has("axis")) {
    m.missing("axis");
  }
  if (const auto w = read_window(m, "trip")) {
    p.sim_trip = *w;
  } else if (!m.has("trip")) {
    m.missing("trip");
  }
  p.sim_hysteresis = m.number_or("hysteresis", p.sim_hysteresis, Bound::NonNegative);
  p.sim_noise = m.number_or("noise", p.sim_noise, Bound::NonNegative);
}

void read_tool_changer(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("tool_changer");
  if (t == nullptr) return;
  Section s(*t, "tool_changer", {"sim", "pockets"}, top.reporter());
  profile.tool_changer = true;
  profile.tool_changer_pockets = static_cast<int>(s.integer("pockets", 1, 10000).value_or(0));
  profile.tool_changer_sim.present = true;
  const toml::table* st = s.subtable("sim");
  if (st == nullptr) return;
  Section m(*st, "tool_changer.sim", {"prepare_time_s", "change_time_s"}, top.reporter());
  auto& sim = profile.tool_changer_sim;
  sim.prepare_time_s = m.number_or("prepare_time_s", sim.prepare_time_s, Bound::NonNegative);
  sim.change_time_s = m.number_or("change_time_s", sim.change_time_s, Bound::NonNegative);
}

namespace {

/// [process.cutting]: the torch's outputs, times and heights (checked against [io] later: the
/// output channels must exist).
void read_cutting(Section& process, MachineProfile& profile) {
  const toml::table* t = process.subtable("cutting");
  if (t == nullptr) return;
  Section s(*t, "process.cutting",
            {"torch_output", "preheat_output", "cut_output", "ignite_s", "preheat_s", "pierce_s", "safe_height",
             "pierce_lift", "approach_feed", "retrace_feed"},
            process.reporter());
  CuttingProfile& c = profile.cutting;
  c.present = true;
  const auto channel = [&](std::string_view key, int fallback) {
    const auto v = s.integer(key, 0, machine::kDigitalChannels - 1);
    if (v && *v >= profile.io.digital_outputs)
      s.error(key,
              fmt::format("{} is digital output {}, but the machine has {} (io.digital_outputs)", s.key_path(key), *v,
                          profile.io.digital_outputs),
              "config.range");
    return static_cast<int>(v.value_or(fallback));
  };
  c.torch_output = channel("torch_output", -1);
  // A plasma torch is lit by its own stage (M190 replayed at a resume), not by an output.
  if (c.torch_output < 0 && !s.has("torch_output") && !process.has("plasma") && !process.has("oxyfuel"))
    s.missing("torch_output");  // a torch stage lights its own torch
  c.preheat_output = channel("preheat_output", -1);
  c.cut_output = channel("cut_output", -1);
  c.ignite_s = s.number_or("ignite_s", 0, Bound::NonNegative);
  c.preheat_s = s.number_or("preheat_s", 0, Bound::NonNegative);
  c.pierce_s = s.number_or("pierce_s", 0, Bound::NonNegative);
  if (const auto h = s.number("safe_height")) {
    c.safe_height_mm = *h;
    c.has_safe_height = true;
  }
  c.pierce_lift_mm = s.number_or("pierce_lift", 0, Bound::NonNegative);
  c.approach_mm_min = s.number_or("approach_feed", 0, Bound::NonNegative);
  c.retrace_mm_min = s.number_or("retrace_feed", c.retrace_mm_min, Bound::Positive);
}

}  // namespace

void read_process(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("process");
  if (t == nullptr) return;
  Section s(*t, "process", {"torch", "generator", "sim", "cutting", "broaching", "plasma", "oxyfuel"},
            top.reporter());
  machine::SimProcessConfig& p = profile.process;
  p.torch = s.boolean_or("torch", false);
  p.generator = s.boolean_or("generator", false);
  read_cutting(s, profile);
  read_broaching(s, profile);
  read_plasma(s, profile);
  read_oxyfuel(s, profile);
  const toml::table* st = s.subtable("sim");
  if (st == nullptr) return;
  Section m(*st, "process.sim", {"arc_delay_s"}, top.reporter());
  p.arc_delay_s = m.number_or("arc_delay_s", p.arc_delay_s, Bound::NonNegative);
  if (!p.torch) m.reject("arc_delay_s", "needs process.torch = true");
}

void read_io(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("io");
  if (t == nullptr) return;
  Section s(*t, "io", {"digital_inputs", "digital_outputs", "analog_inputs", "analog_outputs"},
            top.reporter());
  IoProfile& io = profile.io;
  auto count = [&](std::string_view key, int fallback, int max) {
    return static_cast<int>(s.integer(key, 0, max).value_or(fallback));
  };
  io.digital_inputs = count("digital_inputs", io.digital_inputs, machine::kDigitalChannels);
  io.digital_outputs = count("digital_outputs", io.digital_outputs, machine::kDigitalChannels);
  io.analog_inputs = count("analog_inputs", io.analog_inputs, machine::kAnalogChannels);
  io.analog_outputs = count("analog_outputs", io.analog_outputs, machine::kAnalogChannels);
}

namespace {

std::string resolve(const std::filesystem::path& base_dir, const std::string& path) {
  const std::filesystem::path p(path);
  return (p.is_absolute() || base_dir.empty() ? p : base_dir / p).lexically_normal().string();
}

}  // namespace

void read_interpreter(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir) {
  const toml::table* t = top.subtable("interpreter");
  if (t == nullptr) return;
  Section s(*t, "interpreter",
            {"dialect", "machine", "axis_map", "subroutine_path", "tool_table", "readahead_moves",
             "readahead_s", "max_scan_s"},
            top.reporter());
  InterpreterOptions& o = profile.interpreter;
  o.dialect =
      s.choice<Dialect>("dialect", {{"linuxcnc", Dialect::LinuxCnc}, {"fanuc", Dialect::Fanuc}}, o.dialect);
  o.machine = s.choice<MachineKind>("machine", {{"mill", MachineKind::Mill}, {"lathe", MachineKind::Lathe}}, o.machine);
  if (const auto map = s.string("axis_map")) {
    if (const std::string problem = parse_axis_map(*map, o.axis_map); !problem.empty())
      s.error("axis_map", "interpreter.axis_map: " + problem, "config.range");
  }
  if (const toml::node* n = s.find("subroutine_path")) {
    const toml::array* list = n->as_array();
    const bool all_strings = list != nullptr && list->is_homogeneous(toml::node_type::string);
    if (!n->is_string() && !all_strings) {
      s.error("subroutine_path", "interpreter.subroutine_path must be a folder or an array of folders",
              "config.type");
    } else if (n->is_string()) {
      o.subroutine_path.push_back(resolve(base_dir, n->as_string()->get()));
    } else {
      for (const toml::node& e : *list) o.subroutine_path.push_back(resolve(base_dir, e.as_string()->get()));
    }
    for (const std::string& dir : o.subroutine_path) {
      std::error_code ec;
      if (!std::filesystem::is_directory(dir, ec)) {
        s.warning("subroutine_path", fmt::format("interpreter.subroutine_path: {} is not a folder", dir),
                  "config.path");
      }
    }
  }
  if (const auto table = s.string("tool_table")) {
    o.tool_table = resolve(base_dir, *table);
    // Checked now, not when the first program runs: a missing table, a folder or a device.
    if (const std::string why = unreadable_input(o.tool_table); !why.empty())
      s.error("tool_table", fmt::format("interpreter.tool_table: {}: {}", o.tool_table, why), "config.path");
  }
  o.readahead_moves = static_cast<int>(s.integer("readahead_moves", 1, 10'000'000).value_or(o.readahead_moves));
  o.readahead_s = s.number_or("readahead_s", o.readahead_s, Bound::Positive);
  o.max_scan_s = s.number_or("max_scan_s", o.max_scan_s, Bound::Positive);
}

void read_planner(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("planner");
  if (t == nullptr) return;
  Section s(*t, "planner", {"lookahead", "default_tolerance"}, top.reporter());
  PlannerOptions& p = profile.planner;
  p.lookahead = static_cast<int>(s.integer("lookahead", 1, 100000).value_or(p.lookahead));
  p.default_tolerance = s.number_or("default_tolerance", p.default_tolerance, Bound::NonNegative);
}

}  // namespace opencnc::config::detail
