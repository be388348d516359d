// SPDX-License-Identifier: GPL-3.0-or-later
// TorchHeight: a cut chart material's settings in place of the profile's for the rest of the run
// (control/torch_height.hpp, machine/cut_chart_codes.hpp, docs/cutting.md "Cut charts").
#include "opencnc/control/torch_height.hpp"
#include "opencnc/machine/cut_chart_codes.hpp"

namespace opencnc::control {

bool TorchHeight::apply_chart_code(int code, double p) noexcept {
  switch (code) {
    case machine::kMaterialCode:  // the number alone: its settings follow as the codes below
      return true;
    case machine::kChartPierceHeightCode:
      config_.pierce_height_mm = p;
      return true;
    case machine::kChartPierceDelayCode:
      config_.pierce_delay_s = p;
      return true;
    case machine::kChartCutHeightCode:
      config_.cut_height_mm = p;
      return true;
    case machine::kChartArcVoltageCode:
      config_.arc_voltage_v = p > 0 ? p : profile_.arc_voltage_v;
      return true;
    case machine::kChartPuddleHeightCode:
      config_.puddle_height_mm = p;
      return true;
    case machine::kChartPuddleDelayCode:
      config_.puddle_delay_s = p;
      return true;
    case machine::kChartPreheatCode:
      config_.preheat_s = p > 0 ? p : profile_.preheat_s;
      return true;
    default:
      return false;
  }
}

}  // namespace opencnc::control
