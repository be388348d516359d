// SPDX-License-Identifier: GPL-3.0-or-later
// PowerFailRecorder: the coupled stop's helix error from the trace, the independent stop simulated
// from the state at the signal.
#include "opencnc/broaching/power_fail_recorder.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "opencnc/controller/controller_status.hpp"

namespace opencnc::broaching {

namespace {

/// Bound of the independent stop's simulation (a minute of braking: every real stop is shorter).
constexpr int kMaxStopPeriods = 60000;

}  // namespace

PowerFailRecorder::PowerFailRecorder(const motion::CouplingConfig& coupling,
                                     const plan::MachineLimits& limits, double period_s, double radius_mm)
    : coupling_(coupling), limits_(limits), period_s_(period_s), radius_mm_(radius_mm) {}

motion::CouplingLaw PowerFailRecorder::law_of(const control::CouplingStatus& c) const {
  return motion::law_for(coupling_, c.kind, c.pitch_mm, c.pitch_rate, c.table);
}

void PowerFailRecorder::on_status(const controller::ControllerStatus& s) {
  if (stopping_) {
    report_.dc_link_min_v = std::min(report_.dc_link_min_v, s.servo.dc_link_v);
  }
  if (s.servo.coupling.kind == motion::CouplingKind::Off) return;
  const control::CouplingStatus& c = s.servo.coupling;
  if (c.kind != status_.kind || c.table != status_.table || c.pitch_mm != status_.pitch_mm ||
      c.pitch_rate != status_.pitch_rate || c.master_origin != status_.master_origin ||
      c.slave_origin != status_.slave_origin) {
    status_ = c;
    law_ = law_of(c);
  }
}

// |C − law(Z)| as an arc on the bore: degrees to radians times the radius, in µm.
double PowerFailRecorder::helix_error_um(double master, double slave) const {
  const double law = status_.slave_origin + law_.slave(master - status_.master_origin);
  return std::fabs(slave - law) * std::numbers::pi / 180.0 * radius_mm_ * 1000.0;
}

void PowerFailRecorder::on_trace(const control::TraceSample& s, const controller::TraceContext&) {
  const int m = coupling_.master_axis, sl = coupling_.slave_axis;
  if (s.power_stop && !report_.happened) {
    report_.happened = true;
    report_.coupled = s.coupled && law_.active();
    report_.signal_s = static_cast<double>(s.tick) * period_s_;
    report_.dc_link_min_v = 1e300;
    stopping_ = true;
    master_at_signal_ = s.commanded[m];
    report_.energy_at_signal_j = report_.energy_at_rest_j = s.dc_link_energy_j;
    if (report_.coupled && previous_) simulate_independent_stop(*previous_, s);
  }
  if (stopping_) {
    if (s.coupled && law_.active()) {
      report_.coupled_error_um =
          std::max(report_.coupled_error_um, helix_error_um(s.actual[m], s.actual[sl]));
      report_.coupled_command_error_um =
          std::max(report_.coupled_command_error_um, helix_error_um(s.commanded[m], s.commanded[sl]));
    }
    const bool moving = previous_ && previous_->commanded[m] != s.commanded[m];
    if (moving) {
      report_.stop_time_s = static_cast<double>(s.tick) * period_s_ - report_.signal_s;
      report_.stop_distance_mm = std::fabs(s.commanded[m] - master_at_signal_);
      report_.energy_at_rest_j = s.dc_link_energy_j;
    }
    report_.decel_scale = std::max(report_.decel_scale, s.stop_decel_scale);
  }
  previous_ = s;
}

// Each axis from its commanded position and velocity at the signal, braking at its own
// acceleration limit until it rests, period by period; the helix error of the pair throughout.
void PowerFailRecorder::simulate_independent_stop(const control::TraceSample& before,
                                                  const control::TraceSample& at) {
  const int axes[2] = {coupling_.master_axis, coupling_.slave_axis};
  double x[2], v[2], a[2];
  for (int k = 0; k < 2; ++k) {
    const int i = axes[k];
    x[k] = at.commanded[i];
    v[k] = (at.commanded[i] - before.commanded[i]) / period_s_;
    a[k] = limits_.axis[static_cast<std::size_t>(i)].max_acceleration;
  }
  double worst = helix_error_um(x[0], x[1]);
  for (int n = 0; n < kMaxStopPeriods && (v[0] != 0 || v[1] != 0); ++n) {
    for (int k = 0; k < 2; ++k) {
      const double dv = a[k] * period_s_;
      const double v_next = std::fabs(v[k]) <= dv ? 0.0 : v[k] - std::copysign(dv, v[k]);
      x[k] += 0.5 * (v[k] + v_next) * period_s_;
      v[k] = v_next;
    }
    worst = std::max(worst, helix_error_um(x[0], x[1]));
  }
  report_.independent_error_um = worst;
}

std::string PowerFailRecorder::report_text() const {
  const PowerFailReport& p = report_;
  if (!p.happened) return "power fail          none (the run ended before the injected time)\n";
  std::string out = fmt::format(
      "power fail at       {:.3f} s: stopped in {:.3f} s over {:.3f} mm, DC link down to {:.0f} V\n",
      p.signal_s, p.stop_time_s, p.stop_distance_mm, p.dc_link_min_v);
  if (p.energy_at_signal_j > 0 || p.decel_scale > 1)
    out += fmt::format(
        "DC link energy      {:.2f} J at the signal, {:.2f} J at rest; braked at {:.3f}x the planned "
        "deceleration\n",
        p.energy_at_signal_j, p.energy_at_rest_j, p.decel_scale);
  if (p.coupled)
    out += fmt::format(
        "helix error         {:.3f} um coupled ({:.6f} um commanded), {:.1f} um if each axis stopped alone\n",
        p.coupled_error_um, p.coupled_command_error_um, p.independent_error_um);
  return out;
}

std::string PowerFailRecorder::report_json() const {
  const PowerFailReport& p = report_;
  nlohmann::json j;
  j["happened"] = p.happened;
  j["coupled"] = p.coupled;
  j["signal_s"] = p.signal_s;
  j["stop_time_s"] = p.stop_time_s;
  j["stop_distance_mm"] = p.stop_distance_mm;
  j["coupled_error_um"] = p.coupled_error_um;
  j["coupled_command_error_um"] = p.coupled_command_error_um;
  j["independent_error_um"] = p.independent_error_um;
  j["dc_link_min_v"] = p.happened ? nlohmann::json(p.dc_link_min_v) : nlohmann::json(nullptr);
  j["energy_at_signal_j"] = p.energy_at_signal_j;
  j["energy_at_rest_j"] = p.energy_at_rest_j;
  j["decel_scale"] = p.decel_scale;
  return j.dump();
}

}  // namespace opencnc::broaching
