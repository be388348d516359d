// SPDX-License-Identifier: GPL-3.0-or-later
// EdmRecorder — an observer of the trace that measures a sinker EDM's run: the gap voltage's
// share in band, shorts and their recovery, arcs, jumps, the depth burnt (docs/edm.md).
#pragma once

#include <cstdint>

#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/machine/edm.hpp"

namespace opencnc::edm {

/// What `opencnc run --report` writes under `edm`.
struct EdmReport {
  /// Share of machining time (generator pulsing, from each burn's first discharge on) whose
  /// measured gap voltage was within ±10 % of the active condition's servo reference.
  double gap_voltage_in_band_fraction = 0;
  double machining_s = 0;
  std::uint64_t shorts = 0;            ///< times the gap went into a short
  std::uint64_t shorts_uncleared = 0;  ///< of them, still shorted when their burn or the run ended
  std::uint64_t arc_periods = 0;       ///< servo periods in which the gap arced
  std::uint64_t arcs = 0;              ///< times the gap went into arcing (from another state)
  /// Longest short: from its first period to a discharge again, or, for one that never cleared,
  /// to the end of its burn (M181, the run's end, the fault that stopped it) or of the trace.
  double short_recovery_max_s = 0;
  double depth_mm = 0;  ///< deepest burn: along the work's direction from its first discharge
  std::uint64_t jumps = 0;
  double finishing_s = 0;  ///< of the machining time, the finishing cycle's (the path at rest)
  /// Adaptive control: the windows in which it changed a setting, and the range each setting in
  /// force covered while the generator pulsed (equal ends: it did not move).
  std::uint64_t adaptations = 0;
  double servo_reference_v[2] = {0, 0};
  double gain_mm_s_per_v[2] = {0, 0};
  double jump_period_s[2] = {0, 0};
  double jump_height_mm[2] = {0, 0};
};

/// Controller thread (an observer with trace on); its report section (`edm`) after the run.
class EdmRecorder final : public controller::ControllerObserver, public controller::ReportSection {
 public:
  EdmRecorder(const machine::EdmConfig& edm, double period_s);
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override;
  EdmReport report() const;

  std::string report_key() const override { return "edm"; }
  /// "edm  … s machining, gap voltage in band … %, … jumps, deepest burn … mm" and "edm gap  …
  /// shorts (…), … arcs (… periods)".
  std::string report_text() const override;
  /// The report's values by their names (`gap_voltage_in_band_fraction`, `machining_s`, …).
  std::string report_json() const override;

 private:
  void end_short(std::uint64_t tick, bool cleared);
  void note_settings(const control::EdmStatus& e);

  machine::EdmConfig edm_;
  double period_s_;
  EdmReport r_;
  std::uint64_t in_band_ = 0, machining_ = 0;
  bool burning_ = false;  ///< a condition is on and the gap has sparked since it came on
  double burn_start_ = 0;
  machine::GapState last_ = machine::GapState::Open;
  std::uint64_t short_since_ = 0;
  bool shorted_ = false;
  std::uint64_t last_tick_ = 0;  ///< the newest sample's
  bool first_ = true;
  std::uint32_t jumps_at_start_ = 0, jumps_now_ = 0;
  std::uint64_t finishing_ = 0;
  std::uint32_t adaptations_at_start_ = 0, adaptations_now_ = 0;
  bool settings_seen_ = false;
};

}  // namespace opencnc::edm
