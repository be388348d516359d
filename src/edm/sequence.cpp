// SPDX-License-Identifier: GPL-3.0-or-later
// The roughing-to-finishing condition sequence from the technology table (edm/sequence.hpp): the
// roughing by the electrode's area, the steps down by Ra, the walls back from the undersize.
#include "opencnc/edm/sequence.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

namespace opencnc::edm {

namespace {

using machine::EdmCondition;

/// A condition meets a finish within the rounding of the VDI 3400 table's Ra (VDI 18 is listed
/// as Ra 0.80 µm, 10^(18/20)/10 = 0.794 µm): 2 %.
constexpr double kFinishTolerance = 1.02;

/// The conditions of the technology table the electrode's area takes: those giving an Ra and a
/// side gap whose peak current is within the current density over the area.
std::vector<const EdmCondition*> table_of(const machine::EdmConfig& edm) {
  std::vector<const EdmCondition*> out;
  for (int i = 0; i < edm.condition_count; ++i) {
    const EdmCondition& c = edm.conditions[static_cast<std::size_t>(i)];
    if (c.ra_um > 0 && c.side_gap_mm > 0) out.push_back(&c);
  }
  return out;
}

/// Of `among`, the one `better` prefers (nullptr when empty).
template <class Better>
const EdmCondition* best(const std::vector<const EdmCondition*>& among, Better better) {
  const EdmCondition* b = nullptr;
  for (const EdmCondition* c : among)
    if (b == nullptr || better(*c, *b)) b = c;
  return b;
}

/// The next step below `cur`: the finest condition no finer than half its Ra, else the next finer
/// one; never finer than `floor_ra` (the final step's). Ties: the higher removal rate.
const EdmCondition* next_step(const std::vector<const EdmCondition*>& usable, const EdmCondition& cur,
                              double floor_ra) {
  std::vector<const EdmCondition*> finer, within;
  for (const EdmCondition* c : usable) {
    if (c->ra_um >= cur.ra_um || c->ra_um < floor_ra) continue;
    finer.push_back(c);
    if (c->ra_um >= 0.5 * cur.ra_um) within.push_back(c);
  }
  auto faster = [](const EdmCondition& a, const EdmCondition& b) {
    return a.removal_mm3_min > b.removal_mm3_min;
  };
  if (!within.empty())
    return best(within, [&](const EdmCondition& a, const EdmCondition& b) {
      return a.ra_um < b.ra_um || (a.ra_um == b.ra_um && faster(a, b));
    });
  return best(finer, [&](const EdmCondition& a, const EdmCondition& b) {
    return a.ra_um > b.ra_um || (a.ra_um == b.ra_um && faster(a, b));
  });
}

std::string mm(double v) {
  return fmt::format("{:.4f}", v);
}

}  // namespace

double vdi_to_ra_um(double vdi) noexcept {
  return std::pow(10.0, vdi / 20.0) / 10.0;
}

int ra_to_vdi(double ra_um) noexcept {
  return static_cast<int>(std::lround(20.0 * std::log10(10.0 * ra_um)));
}

std::variant<double, std::string> parse_finish(const std::string& text) {
  std::string t;
  for (const char ch : text) t.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(ch))));
  bool vdi = false;
  if (t.rfind("vdi", 0) == 0) {
    vdi = true;
    t.erase(0, 3);
  } else if (t.rfind("ra", 0) == 0) {
    t.erase(0, 2);
  }
  double v = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  const std::string what = fmt::format(
      "--finish \"{}\" is not a finish: an Ra in µm (\"0.8\", \"Ra0.8\") or a VDI 3400 class (\"VDI18\")",
      text);
  if (t.empty() || ec != std::errc{} || end != t.data() + t.size() || !std::isfinite(v)) return what;
  if (vdi) {
    if (v < 0 || v > 45) return fmt::format("--finish VDI {}: a VDI 3400 class is from 0 to 45", t);
    return vdi_to_ra_um(v);
  }
  if (v <= 0 || v > 50) return fmt::format("--finish Ra {} µm: an Ra above 0 and at most 50 µm", t);
  return v;
}

std::variant<Sequence, std::string> plan_sequence(const machine::EdmConfig& edm, const SequenceRequest& r) {
  if (!(r.area_mm2 > 0) || !std::isfinite(r.area_mm2))
    return fmt::format("the electrode's frontal area must be above 0 mm² (it is {})", r.area_mm2);
  if (!(r.finish_ra_um > 0) || !std::isfinite(r.finish_ra_um))
    return fmt::format("the finish must be an Ra above 0 µm (it is {})", r.finish_ra_um);
  if (!(r.undersize_mm > 0) || !std::isfinite(r.undersize_mm))
    return fmt::format("the electrode's undersize must be above 0 mm per side (it is {})", r.undersize_mm);
  const std::vector<const EdmCondition*> table = table_of(edm);
  if (table.empty())
    return std::string(
        "the machine's conditions make no technology table: none gives both ra_um and side_gap_mm "
        "([[edm.condition]] in its profile)");
  if (!(edm.current_density_max_a_mm2 > 0))
    return std::string(
        "the profile gives no [edm] current_density_max_a_mm2: the roughing cannot be chosen by the "
        "electrode's area");
  const double most_a = edm.current_density_max_a_mm2 * r.area_mm2;
  std::vector<const EdmCondition*> usable;
  for (const EdmCondition* c : table)
    if (c->peak_current_a <= most_a + 1e-9) usable.push_back(c);
  if (usable.empty()) {
    const EdmCondition* least = best(table, [](const EdmCondition& a, const EdmCondition& b) {
      return a.peak_current_a < b.peak_current_a;
    });
    return fmt::format(
        "an electrode of {} mm² takes at most {:.3g} A ({} A/mm²); the table's smallest condition, E{}, runs "
        "{} A",
        r.area_mm2, most_a, edm.current_density_max_a_mm2, least->number, least->peak_current_a);
  }
  std::vector<const EdmCondition*> meeting;
  for (const EdmCondition* c : usable)
    if (c->ra_um <= r.finish_ra_um * kFinishTolerance) meeting.push_back(c);
  if (meeting.empty()) {
    const EdmCondition* finest =
        best(usable, [](const EdmCondition& a, const EdmCondition& b) { return a.ra_um < b.ra_um; });
    return fmt::format(
        "no condition this electrode takes finishes to Ra {:.3g} µm (VDI {}): the finest, E{}, leaves Ra {} "
        "µm",
        r.finish_ra_um, ra_to_vdi(r.finish_ra_um), finest->number, finest->ra_um);
  }
  const EdmCondition* final_step =
      best(meeting, [](const EdmCondition& a, const EdmCondition& b) { return a.ra_um > b.ra_um; });
  std::vector<const EdmCondition*> rough;
  for (const EdmCondition* c : usable)
    if (c->ra_um >= final_step->ra_um) rough.push_back(c);
  const EdmCondition* roughing = best(rough, [](const EdmCondition& a, const EdmCondition& b) {
    return a.removal_mm3_min > b.removal_mm3_min ||
           (a.removal_mm3_min == b.removal_mm3_min && a.peak_current_a > b.peak_current_a);
  });
  std::vector<const EdmCondition*> chosen{roughing};
  while (chosen.back()->ra_um > final_step->ra_um) {
    const EdmCondition* n = next_step(usable, *chosen.back(), final_step->ra_um);
    if (n == nullptr) break;  // cannot happen: final_step itself is finer and within the floor
    chosen.push_back(n);
  }
  // The walls, back from the undersize: each step stops short of the next one's by its own Rz.
  Sequence s;
  s.request = r;
  s.steps.resize(chosen.size());
  double wall = r.undersize_mm;
  for (std::size_t k = chosen.size(); k-- > 0;) {
    const EdmCondition& c = *chosen[k];
    SequenceStep& st = s.steps[k];
    // This step leaves its own roughness (Rz) for the next one to remove.
    if (k + 1 < chosen.size()) wall -= kRzPerRa * c.ra_um * 1e-3;
    st.condition = c.number;
    st.peak_current_a = c.peak_current_a;
    st.ra_um = c.ra_um;
    st.side_gap_mm = c.side_gap_mm;
    st.removal_mm3_min = c.removal_mm3_min;
    st.wear_ratio = c.electrode_wear_ratio;
    st.allowance_mm = r.undersize_mm - wall;
    const double planned = wall - c.side_gap_mm;
    const bool orbits = c.orbit != machine::OrbitKind::None;
    const bool last = k + 1 == chosen.size();
    if (planned < -1e-9) {
      if (last)
        return fmt::format(
            "the undersize {} mm is below E{}'s side gap ({} mm): the electrode would burn the "
            "cavity oversize",
            mm(r.undersize_mm), c.number, mm(c.side_gap_mm));
      return fmt::format(
          "the undersize {} mm is too small for this sequence: E{}'s side gap ({} mm) and the {} mm the "
          "later "
          "steps remove need at least {} mm",
          mm(r.undersize_mm), c.number, mm(c.side_gap_mm), mm(st.allowance_mm),
          mm(c.side_gap_mm + st.allowance_mm));
    }
    if (last && !orbits && planned > 0.0005)
      return fmt::format("E{}, the finishing step, has no orbit: the undersize must be its side gap ({} mm)",
                         c.number, mm(c.side_gap_mm));
    if (last && orbits && planned > c.orbit_radius_mm + 1e-9)
      return fmt::format("E{}'s orbit reaches at most {} mm: an undersize of at most {} mm with it", c.number,
                         mm(c.orbit_radius_mm), mm(c.orbit_radius_mm + c.side_gap_mm));
    st.orbit_mm = orbits ? std::clamp(planned, 0.001, c.orbit_radius_mm) : 0.0;
    st.orbit_limited = orbits && planned > c.orbit_radius_mm + 1e-9;
    st.wall_mm = st.orbit_mm + c.side_gap_mm;
  }
  return s;
}

std::string sequence_text(const Sequence& s) {
  const SequenceRequest& r = s.request;
  std::string out = fmt::format(
      "condition sequence for a frontal area of {} mm², finish Ra {:.3g} µm (VDI {}), undersize {} mm per "
      "side\n",
      r.area_mm2, r.finish_ra_um, ra_to_vdi(r.finish_ra_um), mm(r.undersize_mm));
  out +=
      "step  cond  peak A  Ra µm  VDI  side gap mm  orbit mm  wall mm  allowance mm  removal mm³/min  wear\n";
  for (std::size_t k = 0; k < s.steps.size(); ++k) {
    const SequenceStep& st = s.steps[k];
    out += fmt::format(
        "{:>4}  E{:<3}  {:>6.3g}  {:>5.3g}  {:>3}  {:>11}  {:>8}  {:>7}  {:>12}  {:>15.3g}  {:.0f} %{}\n",
        k + 1, st.condition, st.peak_current_a, st.ra_um, ra_to_vdi(st.ra_um), mm(st.side_gap_mm),
        st.orbit_mm > 0 ? mm(st.orbit_mm) : std::string("-"), mm(st.wall_mm), mm(st.allowance_mm),
        st.removal_mm3_min, 100 * st.wear_ratio, st.orbit_limited ? "  (the condition's largest orbit)" : "");
  }
  return out;
}

std::string sequence_program(const Sequence& s, const machine::EdmConfig& edm, char axis_letter,
                             double surface, double depth_mm, double lift) {
  const SequenceRequest& r = s.request;
  std::string out = fmt::format(
      "(EDM condition sequence: frontal area {} mm2, finish Ra {:.3g} um = VDI {}, undersize {} mm per "
      "side)\n",
      r.area_mm2, r.finish_ra_um, ra_to_vdi(r.finish_ra_um), mm(r.undersize_mm));
  out += fmt::format("(written by opencnc edm sequence; the burn from {}{} to {} mm deep)\n", axis_letter,
                     mm(surface), mm(depth_mm));
  for (std::size_t k = 0; k < s.steps.size(); ++k) {
    const SequenceStep& st = s.steps[k];
    out += fmt::format("(step {}: E{}, Ra {:.3g} um, side gap {} mm, orbit {} mm, wall {} mm, {} mm left)\n",
                       k + 1, st.condition, st.ra_um, mm(st.side_gap_mm), mm(st.orbit_mm), mm(st.wall_mm),
                       mm(st.allowance_mm));
  }
  out += "G21 G90\n";
  out += fmt::format("G0 {}{}\n", axis_letter, mm(surface + lift * 0.05));
  for (const SequenceStep& st : s.steps) {
    const EdmCondition* c = edm.find(st.condition);
    out += st.orbit_mm > 0 ? fmt::format("M180 P{} Q{}\n", st.condition, mm(st.orbit_mm))
                           : fmt::format("M180 P{}\n", st.condition);
    const double feed = c != nullptr ? 60.0 * c->max_forward_mm_s : 60.0;
    out += fmt::format("G1 {}{} F{:.4g}\n", axis_letter, mm(surface - lift * (depth_mm - st.allowance_mm)),
                       feed);
  }
  out += "M181\n";
  out += fmt::format("G0 {}{}\n", axis_letter, mm(surface + lift * 5.0));
  out += "M2\n";
  return out;
}

}  // namespace opencnc::edm
