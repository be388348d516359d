// SPDX-License-Identifier: GPL-3.0-or-later
// The `edm` part of `opencnc run`'s report.
#include "edm_report.hpp"

#include <fmt/format.h>

namespace opencnc::cli {

nlohmann::json edm_json(const control::EdmReport& e, const std::optional<SimEdmFigures>& sim) {
  nlohmann::json j;
  j["gap_voltage_in_band_fraction"] = e.gap_voltage_in_band_fraction;
  j["machining_s"] = e.machining_s;
  j["shorts"] = e.shorts;
  j["shorts_uncleared"] = e.shorts_uncleared;
  j["arcs"] = e.arcs;
  j["arc_periods"] = e.arc_periods;
  j["short_recovery_max_s"] = e.short_recovery_max_s;
  j["depth_mm"] = e.depth_mm;
  j["jumps"] = e.jumps;
  if (sim) {
    j["cavity_oversize_mm"] = sim->cavity_oversize_mm;
    j["electrode_wear_mm"] = sim->electrode_wear_mm;
    j["cavity_depth_mm"] = sim->cavity_depth_mm;
  }
  return j;
}

void print_edm(const control::EdmReport& e, const std::optional<SimEdmFigures>& sim) {
  fmt::print(
      "edm                 {:.1f} s machining, gap voltage in band {:.1f} %, {} jumps, deepest burn "
      "{:.4f} mm\n",
      e.machining_s, 100 * e.gap_voltage_in_band_fraction, e.jumps, e.depth_mm);
  fmt::print("edm gap             {} shorts ({} never cleared; longest {:.3f} s), {} arcs ({} periods)\n",
             e.shorts, e.shorts_uncleared, e.short_recovery_max_s, e.arcs, e.arc_periods);
  if (sim) {
    fmt::print(
        "edm simulated work  cavity {:.4f} mm over the electrode a side, {:.4f} mm deep; "
        "electrode wear up to {:.4f} mm\n",
        sim->cavity_oversize_mm, sim->cavity_depth_mm, sim->electrode_wear_mm);
  }
}

}  // namespace opencnc::cli
