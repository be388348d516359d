// SPDX-License-Identifier: GPL-3.0-or-later
// [kinematics]: the five-axis machine's structure and its two rotary axes (which joint, the
// direction it turns about and a point on it), checked against the profile's axes.
#include <fmt/format.h>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

/// What a rotary axis' pivot is measured from, for the error texts.
const char* pivot_meaning(kinematics::Structure s, std::size_t i) {
  const bool head = s == kinematics::Structure::HeadHead || (s == kinematics::Structure::HeadTable && i == 0);
  return head ? "relative to the spindle's gauge point with every rotary axis at 0, mm"
              : "in machine coordinates with every rotary axis at 0, mm";
}

/// The second axis against the first: another joint, and not parallel to it (two parallel axes
/// turn the tool about one direction only).
void check_pair(Section& second, const kinematics::Config& k) {
  const kinematics::RotaryAxis& a = k.rotary[0];
  const kinematics::RotaryAxis& b = k.rotary[1];
  if (a.joint == b.joint && is_rotary(a.joint)) {
    second.error(
        "axis",
        fmt::format("{}: {} is the first rotary axis already", second.key_path("axis"), letter(a.joint)),
        "config.range");
  } else if (norm(a.direction) > 0 && norm(b.direction) > 0 &&
             norm(cross(a.direction, b.direction)) < 1e-6 * norm(a.direction) * norm(b.direction)) {
    second.error(
        "direction",
        fmt::format("{} is parallel to the first rotary axis: the two could not turn the tool onto every "
                    "direction",
                    second.key_path("direction")),
        "config.range");
  }
}

/// `measured = "probe.reference_sphere"`: B's line as the reference sphere's section keeps it —
/// the drawing's, or what `opencnc calibrate-b --write` measured — so that a calibration moves the
/// kinematics with it rather than leaving a second copy behind.
void take_measured(Section& r, kinematics::RotaryAxis& a, const MachineProfile& profile) {
  const auto from = r.string("measured");
  if (!from) return;
  if (*from != "probe.reference_sphere") {
    r.error(
        "measured",
        fmt::format("{} must be \"probe.reference_sphere\" (it is \"{}\")", r.key_path("measured"), *from),
        "config.range");
    return;
  }
  const ReferenceSphereProfile& sphere = profile.probe.reference_sphere;
  if (a.joint != Axis::B || !sphere.has_b_axis) {
    r.error("measured",
            fmt::format("{}: [probe.reference_sphere] keeps B's axis only, in b_axis (this axis is {}{})",
                        r.key_path("measured"), letter(a.joint),
                        sphere.has_b_axis ? "" : "; and the profile has no probe.reference_sphere.b_axis"),
            "config.range");
    return;
  }
  r.reject("direction",
           "does not apply: the measured axis' direction is probe.reference_sphere.b_axis_direction");
  r.reject("pivot_mm",
           "does not apply: the measured axis crosses the sphere's plane at probe.reference_sphere.b_axis");
  a.direction = sphere.b_axis_direction;
  a.pivot_mm = {sphere.b_axis[0], sphere.position[1], sphere.b_axis[1]};
}

void read_rotary(Section& s, kinematics::Config& k, const MachineProfile& profile) {
  const toml::node* n = s.find("rotary");
  const toml::array* list = n != nullptr ? n->as_array() : nullptr;
  const std::string order = k.structure == kinematics::Structure::HeadTable
                                ? "the head's axis first, then the table's"
                                : "the outer axis (the one that carries the other) first";
  if (list == nullptr || !list->is_array_of_tables() || list->size() != 2) {
    if (n == nullptr) {
      s.missing("rotary");
    } else {
      s.error("rotary",
              fmt::format("kinematics.rotary must be two tables ([[kinematics.rotary]]): {}", order),
              "config.type");
    }
    return;
  }
  for (std::size_t i = 0; i < 2; ++i) {
    Section r(*(*list)[i].as_table(), fmt::format("kinematics.rotary[{}]", i + 1),
              {"axis", "direction", "pivot_mm", "measured"}, s.reporter());
    kinematics::RotaryAxis& a = k.rotary[i];
    const auto word = r.string("axis");
    if (!word && !r.has("axis")) r.missing("axis");
    const AxisProfile* ap = nullptr;
    Axis joint = Axis::X;
    if (word) {
      if (const auto letter_axis = axis_from_letter(*word)) {
        joint = *letter_axis;
        ap = profile.find(joint);
      }
    }
    if (word && (ap == nullptr || !ap->rotary)) {
      r.error(
          "axis",
          fmt::format(
              "{} must name a rotary axis of this machine (A, B or C with an [axis.<letter>]; it is \"{}\")",
              r.key_path("axis"), *word),
          "config.range");
    } else if (ap != nullptr) {
      if (ap->manual())
        r.error("axis",
                fmt::format("{}: a rotary axis of the kinematics must be driven, not fed by hand",
                            r.key_path("axis")),
                "config.range");
      a.joint = joint;
    }
    if (!r.has("measured") &&
        read_triple(r, "direction", a.direction, "the direction it turns about (right-handed)") &&
        !(norm(a.direction) > 0))
      r.error("direction", fmt::format("{} has no length", r.key_path("direction")), "config.range");
    if (r.has("measured")) {
      take_measured(r, a, profile);
    } else {
      read_triple(r, "pivot_mm", a.pivot_mm, pivot_meaning(k.structure, i));
    }
    if (i == 1) check_pair(r, k);
  }
}

}  // namespace

void read_kinematics(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("kinematics");
  if (t == nullptr) return;
  Section s(*t, "kinematics", {"structure", "rotary"}, top.reporter());
  kinematics::Config k;
  if (!s.has("structure")) s.missing("structure");
  k.structure = s.choice<kinematics::Structure>("structure",
                                                {{"identity", kinematics::Structure::Identity},
                                                 {"table-table", kinematics::Structure::TableTable},
                                                 {"head-head", kinematics::Structure::HeadHead},
                                                 {"head-table", kinematics::Structure::HeadTable}},
                                                kinematics::Structure::Identity);
  if (k.structure == kinematics::Structure::Identity) {
    if (s.has("rotary")) s.reject("rotary", "does not apply: an identity kinematics turns no tool");
    profile.kinematics = k;
    return;
  }
  for (const Axis linear : {Axis::X, Axis::Y, Axis::Z}) {
    const AxisProfile* ap = profile.find(linear);
    if (ap == nullptr || ap->manual() || ap->rotary) {
      s.error("structure",
              fmt::format("a {} kinematics needs driven linear X, Y and Z axes ({} is {})",
                          to_string(k.structure), letter(linear),
                          ap == nullptr ? "missing"
                          : ap->rotary  ? "rotary"
                                        : "hand-fed"),
              "config.range");
      return;
    }
  }
  const std::size_t errors = s.reporter().error_count();  // prepare() only on sound axes
  read_rotary(s, k, profile);
  if (s.reporter().error_count() != errors) return;
  const kinematics::ConfigError e = kinematics::prepare(k);
  if (e != kinematics::ConfigError::Ok) {
    s.error("rotary", fmt::format("kinematics.rotary: {}", to_string(e)), "config.range");
    return;
  }
  profile.kinematics = k;
}

}  // namespace opencnc::config::detail
