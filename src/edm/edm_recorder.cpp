// SPDX-License-Identifier: GPL-3.0-or-later
// EdmRecorder: the EDM run's figures from the trace, period by period.
#include "opencnc/edm/edm_recorder.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace opencnc::edm {

EdmRecorder::EdmRecorder(const machine::EdmConfig& edm, double period_s) : edm_(edm), period_s_(period_s) {}

void EdmRecorder::on_trace(const control::TraceSample& s, const controller::TraceContext& /*c*/) {
  const control::EdmStatus& e = s.edm;
  if (first_) {
    jumps_at_start_ = e.jumps;
    adaptations_at_start_ = e.adaptations;
    first_ = false;
  }
  jumps_now_ = e.jumps;
  adaptations_now_ = e.adaptations;
  last_tick_ = s.tick;
  using machine::GapState;
  if (shorted_ && !e.on) end_short(s.tick, false);  // the burn ended shorted (M181, the run's end, a fault)
  const double tool = s.commanded[edm_.tool_axis] - edm_.lift_direction * (e.jumping ? e.jump_lift_mm : 0.0);
  if (!e.on) {
    burning_ = false;
  } else if (!burning_ && e.generator && e.gap_state != GapState::Open) {
    burning_ = true;
    burn_start_ = tool;
  }
  if (burning_ && !e.jumping) r_.depth_mm = std::max(r_.depth_mm, (burn_start_ - tool) * edm_.lift_direction);
  const bool pulsing = burning_ && e.generator;
  if (pulsing) {
    ++machining_;
    // The reference in force (adaptive control moves it); a trace without it: the condition's.
    const machine::EdmCondition* c = edm_.find(e.condition);
    const double ref = e.servo_reference_v > 0 ? e.servo_reference_v
                       : c != nullptr          ? c->servo_reference_v
                                               : 0.0;
    if (ref > 0 && std::fabs(e.gap_voltage_v - ref) <= 0.1 * ref) ++in_band_;
    if (e.finishing) ++finishing_;
    note_settings(e);
    if (e.gap_state == GapState::Arc) {
      ++r_.arc_periods;
      if (last_ != GapState::Arc) ++r_.arcs;
    }
    if (e.gap_state == GapState::Short && !shorted_) {
      shorted_ = true;
      short_since_ = s.tick;
      ++r_.shorts;
    }
  }
  // A short ends at the first discharge after it (normal or arc); lifted or off it is not over.
  if (shorted_ && e.generator && (e.gap_state == GapState::Normal || e.gap_state == GapState::Arc))
    end_short(s.tick, true);
  if (e.generator) last_ = e.gap_state;
}

// The settings in force while the generator pulses: the range each one covered.
void EdmRecorder::note_settings(const control::EdmStatus& e) {
  const double now[4] = {e.servo_reference_v, e.gain_mm_s_per_v, e.jump_period_s, e.jump_height_mm};
  double* range[4] = {r_.servo_reference_v, r_.gain_mm_s_per_v, r_.jump_period_s, r_.jump_height_mm};
  for (int i = 0; i < 4; ++i) {
    range[i][0] = settings_seen_ ? std::min(range[i][0], now[i]) : now[i];
    range[i][1] = settings_seen_ ? std::max(range[i][1], now[i]) : now[i];
  }
  settings_seen_ = true;
}

void EdmRecorder::end_short(std::uint64_t tick, bool cleared) {
  shorted_ = false;
  r_.short_recovery_max_s =
      std::max(r_.short_recovery_max_s, static_cast<double>(tick - short_since_) * period_s_);
  if (!cleared) ++r_.shorts_uncleared;
}

EdmReport EdmRecorder::report() const {
  EdmReport r = r_;
  if (shorted_) {  // still shorted at the last sample: it counts with its time so far
    r.short_recovery_max_s =
        std::max(r.short_recovery_max_s, static_cast<double>(last_tick_ - short_since_) * period_s_);
    ++r.shorts_uncleared;
  }
  r.machining_s = static_cast<double>(machining_) * period_s_;
  r.gap_voltage_in_band_fraction =
      machining_ > 0 ? static_cast<double>(in_band_) / static_cast<double>(machining_) : 0.0;
  r.jumps = jumps_now_ - jumps_at_start_;
  r.finishing_s = static_cast<double>(finishing_) * period_s_;
  r.adaptations = adaptations_now_ - adaptations_at_start_;
  return r;
}

std::string EdmRecorder::report_text() const {
  const EdmReport e = report();
  return fmt::format(
             "edm                 {:.1f} s machining, gap voltage in band {:.1f} %, {} jumps, deepest burn "
             "{:.4f} mm\n",
             e.machining_s, 100 * e.gap_voltage_in_band_fraction, e.jumps, e.depth_mm) +
         fmt::format(
             "edm gap             {} shorts ({} never cleared; longest {:.3f} s), {} arcs ({} periods)\n",
             e.shorts, e.shorts_uncleared, e.short_recovery_max_s, e.arcs, e.arc_periods) +
         (e.adaptations > 0 || e.finishing_s > 0
              ? fmt::format("edm control         {:.1f} s finishing cycle, {} adaptations: reference "
                            "{:.1f}–{:.1f} V, "
                            "gain {:.4f}–{:.4f} mm/s/V, jump every {:.3f}–{:.3f} s, {:.3f}–{:.3f} mm high\n",
                            e.finishing_s, e.adaptations, e.servo_reference_v[0], e.servo_reference_v[1],
                            e.gain_mm_s_per_v[0], e.gain_mm_s_per_v[1], e.jump_period_s[0],
                            e.jump_period_s[1], e.jump_height_mm[0], e.jump_height_mm[1])
              : std::string());
}

std::string EdmRecorder::report_json() const {
  const EdmReport e = report();
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
  j["finishing_s"] = e.finishing_s;
  j["adaptations"] = e.adaptations;
  j["servo_reference_v"] = {e.servo_reference_v[0], e.servo_reference_v[1]};
  j["gain_mm_s_per_v"] = {e.gain_mm_s_per_v[0], e.gain_mm_s_per_v[1]};
  j["jump_period_s"] = {e.jump_period_s[0], e.jump_period_s[1]};
  j["jump_height_mm"] = {e.jump_height_mm[0], e.jump_height_mm[1]};
  return j.dump();
}

}  // namespace opencnc::edm
