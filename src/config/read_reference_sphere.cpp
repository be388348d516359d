// SPDX-License-Identifier: GPL-3.0-or-later
// Reading [probe.reference_sphere]: the sphere electrodes are set against, and its simulation;
// [[sim.electrode]]: the simulated electrodes it measures.
#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

/// `key` as [x, z]: where B's axis crosses machine X and Z; reports and returns false otherwise.
bool read_b_axis(Section& s, std::string_view key, std::array<double, 2>& out) {
  const toml::array* a = s.find(key)->as_array();
  bool ok = a != nullptr && a->size() == 2;
  for (std::size_t i = 0; ok && i < 2; ++i) {
    const std::optional<double> v = (*a)[i].value<double>();
    ok = v.has_value() && std::isfinite(*v);
    if (ok) out[i] = *v;
  }
  if (!ok)
    s.error(key,
            fmt::format("{} must be [x, z]: where B's axis crosses machine X and Z, mm", s.key_path(key)),
            "config.type");
  return ok;
}

/// B's axis turns about Y on this kind of machine: a direction more than this far from Y is a
/// mistake (and would not cross the sphere's plane near the sphere).
constexpr double kMaxTiltFromYDeg = 10.0;

/// `key` (when present) as a direction [x, y, z] within kMaxTiltFromYDeg of Y, made a unit vector.
void read_b_direction(Section& s, std::string_view key, Vec3& out) {
  if (!s.has(key)) return;
  Vec3 d{};
  if (!read_triple(s, key, d)) return;
  const double length = std::hypot(d[0], d[1], d[2]);
  if (!(length > 0) || d[1] < length * std::cos(kMaxTiltFromYDeg * std::numbers::pi / 180)) {
    s.error(key,
            fmt::format("{} must point along +Y within {:g}° (B turns about Y): {}", s.key_path(key),
                        kMaxTiltFromYDeg, length > 0 ? "it does not" : "it has no length"),
            "config.range");
    return;
  }
  for (std::size_t i = 0; i < 3; ++i) out[i] = d[i] / length;
}

void read_sim(Section& s, ReferenceSphereProfile& r) {
  const toml::table* st = s.subtable("sim");
  if (st == nullptr) return;
  Section m(*st, s.path() + ".sim", {"hysteresis", "noise", "b_axis", "b_axis_direction"}, s.reporter());
  r.sim = true;
  r.sim_hysteresis = m.number_or("hysteresis", r.sim_hysteresis, Bound::NonNegative);
  r.sim_noise = m.number_or("noise", r.sim_noise, Bound::NonNegative);
  if (m.has("b_axis")) r.sim_turns_with_b = read_b_axis(m, "b_axis", r.sim_b_axis);
  read_b_direction(m, "b_axis_direction", r.sim_b_direction);
}

}  // namespace

void read_reference_sphere(Section& probe, MachineProfile& profile) {
  const toml::table* t = probe.subtable("reference_sphere");
  if (t == nullptr) return;
  Section s(*t, "probe.reference_sphere",
            {"position", "diameter", "b", "clearance", "probe_feed", "safe_z", "touches_around", "tolerance",
             "max_deviation", "fast_feed", "back_off", "b_axis", "b_axis_direction", "sim"},
            probe.reporter());
  ReferenceSphereProfile& r = profile.probe.reference_sphere;
  r.present = true;
  read_triple(s, "position", r.position);
  r.diameter = s.required_number("diameter", Bound::Positive);
  r.clearance = s.number_or("clearance", r.clearance, Bound::Positive);
  r.probe_feed = s.number_or("probe_feed", r.probe_feed, Bound::Positive);
  r.safe_z = s.required_number("safe_z");
  if (const auto n = s.integer("touches_around", 4, 64)) r.touches_around = static_cast<int>(*n);
  r.tolerance = s.number_or("tolerance", r.tolerance, Bound::Positive);
  r.max_deviation = s.number_or("max_deviation", r.max_deviation, Bound::Positive);
  r.fast_feed = s.number_or("fast_feed", 0, Bound::NonNegative);
  r.back_off = s.number_or("back_off", r.back_off, Bound::Positive);
  if (r.fast_feed > 0 && r.back_off >= r.clearance)
    s.error("back_off",
            fmt::format("{} ({}) must be below the clearance ({}): the slow touch starts off the surface",
                        s.key_path("back_off"), show(r.back_off), show(r.clearance)),
            "config.range");
  if (s.has("b")) {
    r.b_deg = s.number_or("b", 0);
    if (profile.find(Axis::B) == nullptr) s.reject("b", "the profile has no B axis");
  }
  for (const Axis a : {Axis::X, Axis::Y, Axis::Z}) {
    const AxisProfile* ap = profile.find(a);
    if (ap == nullptr || ap->manual()) {
      s.error("position",
              fmt::format("probe.reference_sphere needs driven X, Y and Z axes ({} is {})", letter(a),
                          ap == nullptr ? "missing" : "hand-fed"),
              "config.range");
      return;
    }
  }
  if (r.diameter > 0 && r.safe_z < r.position[2] + r.diameter / 2 + r.clearance) {
    s.error(
        "safe_z",
        fmt::format("probe.reference_sphere.safe_z ({}) is below the sphere's top plus the clearance ({})",
                    show(r.safe_z), show(r.position[2] + r.diameter / 2 + r.clearance)),
        "config.range");
  }
  if (s.has("b_axis")) {
    r.has_b_axis = read_b_axis(s, "b_axis", r.b_axis);
    if (profile.find(Axis::B) == nullptr) s.reject("b_axis", "the profile has no B axis");
  }
  read_b_direction(s, "b_axis_direction", r.b_axis_direction);
  read_sim(s, r);
  if (r.sim_turns_with_b && profile.find(Axis::B) == nullptr)
    s.error("sim", "probe.reference_sphere.sim.b_axis: the profile has no B axis", "config.range");
}

// Each [[sim.electrode]]: a tool number (once), its true offsets and its tip's radius.
void read_sim_electrodes(Section& sim, MachineProfile& profile) {
  const toml::node* n = sim.find("electrode");
  if (n == nullptr) return;
  const toml::array* list = n->as_array();
  if (list == nullptr || !list->is_array_of_tables() ||
      list->size() > static_cast<std::size_t>(machine::kMaxSimElectrodes)) {
    sim.error("electrode",
              fmt::format("sim.electrode must be an array of tables ([[sim.electrode]]), at most {}",
                          machine::kMaxSimElectrodes),
              "config.type");
    return;
  }
  for (std::size_t i = 0; i < list->size(); ++i) {
    Section t(*(*list)[i].as_table(), fmt::format("sim.electrode[{}]", i + 1),
              {"tool", "offset", "tip_radius"}, sim.reporter());
    machine::SimElectrode e;
    const auto tool = t.integer("tool", 1, std::numeric_limits<std::int32_t>::max());
    if (!tool && !t.has("tool")) t.missing("tool");
    e.tool = static_cast<std::int32_t>(tool.value_or(0));
    for (const machine::SimElectrode& other : profile.sim_electrodes)
      if (e.tool != 0 && other.tool == e.tool)
        t.error("tool",
                fmt::format("{}: tool {} has a simulated electrode already", t.key_path("tool"), e.tool),
                "config.range");
    read_triple(t, "offset", e.offset);
    e.tip_radius = t.number_or("tip_radius", 0, Bound::NonNegative);
    profile.sim_electrodes.push_back(e);
  }
}

}  // namespace opencnc::config::detail
