// SPDX-License-Identifier: GPL-3.0-or-later
// CuttingRecorder: the plasma run's figures from every period of the trace.
#include "opencnc/cutting/cutting_recorder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

namespace opencnc::cutting {

namespace {
constexpr double kBandMm = 0.1;
}

CuttingRecorder::CuttingRecorder(const machine::PlasmaConfig& plasma, const machine::SimPlasmaConfig& sim,
                                 double period_s)
    : plasma_(plasma), period_s_(period_s) {
  if (sim.present) plate_.emplace(sim);
}

void CuttingRecorder::on_trace(const control::TraceSample& s, const controller::TraceContext&) {
  const control::TorchStatus& t = s.torch;
  if (first_) {
    first_ = false;
    pierces0_ = t.pierces;
    losses0_ = t.arc_losses;
    failed0_ = t.failed_starts;
    trips0_ = t.float_trips;
    breakaways0_ = t.breakaways;
    preheats0_ = t.preheats;
    starts0_ = t.operator_starts;
    preheat0_s_ = t.preheat_total_s;
  }
  r_.oxy_fuel = plasma_.oxy_fuel();
  r_.preheats = t.preheats - preheats0_;
  r_.operator_starts = t.operator_starts - starts0_;
  r_.preheat_s = t.preheat_total_s - preheat0_s_;
  r_.pierces = t.pierces - pierces0_;
  r_.arc_losses = t.arc_losses - losses0_;
  r_.failed_starts = t.failed_starts - failed0_;
  r_.float_trips = t.float_trips - trips0_;
  r_.breakaways = t.breakaways - breakaways0_;
  if (t.thc_hold && !hold_before_) ++r_.holes_slowed;
  hold_before_ = t.thc_hold;
  if (t.thc == control::ThcState::VoidLock && thc_before_ != control::ThcState::VoidLock) ++r_.void_locks;
  thc_before_ = t.thc;
  // Plasma cuts while the arc burns; oxy-fuel while the stage cuts (the cutting oxygen is on).
  if (t.phase != control::TorchPhase::Cutting || !(t.arc_ok || plasma_.oxy_fuel())) return;
  const auto z = static_cast<std::size_t>(plasma_.z_axis);
  double height = plasma_.cut_height_mm;
  if (plate_) {
    height = s.actual[z] - plate_->z(s.actual[0], s.actual[1]);
  } else if (plasma_.oxy_fuel()) {
    height = t.sensor_height_mm;  // the capacitive sensor's own reading
  } else if (t.target_voltage_v > 0) {
    height += (t.filtered_voltage_v - t.target_voltage_v) / plasma_.volts_per_mm;
  }
  r_.height_measured = plate_.has_value();
  const double error = height - plasma_.cut_height_mm;
  ++cutting_;
  if (std::fabs(error) <= kBandMm) ++in_band_;
  if (t.thc == control::ThcState::Active) ++active_;
  r_.max_dive_mm = std::max(r_.max_dive_mm, -error);
  r_.max_rise_mm = std::max(r_.max_rise_mm, error);
}

CuttingReport CuttingRecorder::report() const {
  CuttingReport r = r_;
  r.cutting_s = static_cast<double>(cutting_) * period_s_;
  r.height_in_band_fraction =
      cutting_ > 0 ? static_cast<double>(in_band_) / static_cast<double>(cutting_) : 0.0;
  r.thc_active_fraction = cutting_ > 0 ? static_cast<double>(active_) / static_cast<double>(cutting_) : 0.0;
  return r;
}

std::string CuttingRecorder::report_text() const {
  const CuttingReport r = report();
  return fmt::format(
             "cutting             {:.2f} s, height within ±0.1 mm of the cut height {:.2f} % ({}), deepest "
             "dive "
             "{:.3f} mm, highest rise {:.3f} mm, THC correcting {:.1f} %\n"
             "cutting torch       {} pierces, {} failed starts, {} arc losses, {} float trips, {} "
             "breakaways, {} "
             "kerf/void locks, {} holes slowed\n",
             r.cutting_s, 100 * r.height_in_band_fraction,
             r.height_measured ? "above the simulated plate"
             : r.oxy_fuel      ? "from the height sensor"
                               : "from the arc voltage",
             r.max_dive_mm, r.max_rise_mm, 100 * r.thc_active_fraction, r.pierces, r.failed_starts,
             r.arc_losses, r.float_trips, r.breakaways, r.void_locks, r.holes_slowed) +
         (r.oxy_fuel
              ? fmt::format(
                    "cutting preheat     {} preheats, {:.2f} s in all, {} ended by the operator's start\n",
                    r.preheats, r.preheat_s, r.operator_starts)
              : std::string());
}

std::string CuttingRecorder::report_json() const {
  const CuttingReport r = report();
  return nlohmann::json{{"height_in_band_fraction", r.height_in_band_fraction},
                        {"max_dive_mm", r.max_dive_mm},
                        {"max_rise_mm", r.max_rise_mm},
                        {"cutting_s", r.cutting_s},
                        {"thc_active_fraction", r.thc_active_fraction},
                        {"arc_losses", r.arc_losses},
                        {"pierces", r.pierces},
                        {"failed_starts", r.failed_starts},
                        {"float_trips", r.float_trips},
                        {"breakaways", r.breakaways},
                        {"holes_slowed", r.holes_slowed},
                        {"void_locks", r.void_locks},
                        {"height_measured", r.height_measured},
                        {"process", r.oxy_fuel ? "oxy-fuel" : "plasma"},
                        {"preheats", r.preheats},
                        {"preheat_s", r.preheat_s},
                        {"operator_starts", r.operator_starts}}
      .dump();
}

}  // namespace opencnc::cutting
