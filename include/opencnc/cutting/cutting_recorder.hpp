// SPDX-License-Identifier: GPL-3.0-or-later
// CuttingRecorder — an observer of the trace that measures a plasma run: the torch's height
// against the cut height while cutting, the deepest dive, arc losses, pierces, holes slowed
// (docs/cutting.md).
#pragma once

#include <cstdint>
#include <optional>

#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/machine/plasma.hpp"
#include "opencnc/machine/sim_plasma_process.hpp"

namespace opencnc::cutting {

/// What `opencnc run --report` writes under `cutting`.
struct CuttingReport {
  /// Share of cutting time (the torch at its cut height or under height control, arc-OK) whose
  /// height above the plate was within ±0.1 mm of the cut height.
  double height_in_band_fraction = 0;
  double max_dive_mm = 0;  ///< the deepest the torch went below the cut height while cutting
  double max_rise_mm = 0;  ///< the highest it went above
  double cutting_s = 0;
  double thc_active_fraction = 0;  ///< of the cutting time, the height control corrected
  std::uint64_t arc_losses = 0;
  std::uint64_t pierces = 0;
  std::uint64_t failed_starts = 0;
  std::uint64_t float_trips = 0;   ///< the float switch while the torch burned (the torch touched the plate)
  std::uint64_t breakaways = 0;    ///< the torch's breakaway switch during a cut
  std::uint64_t holes_slowed = 0;  ///< the height held by the program (M192) at a slowed hole
  std::uint64_t void_locks = 0;    ///< times a voltage jump held the height (kerf crossings)
  bool height_measured =
      false;                   ///< true: the simulated plate's; false: from the arc voltage or height sensor
  bool oxy_fuel = false;       ///< an oxy-fuel torch (`process`: "oxy-fuel"; else "plasma")
  std::uint64_t preheats = 0;  ///< oxy-fuel: preheats begun
  double preheat_s = 0;        ///< oxy-fuel: time spent preheating
  std::uint64_t operator_starts = 0;  ///< oxy-fuel: preheats ended by the operator's start
};

/// Controller thread (an observer with trace on); its report section (`cutting`) after the run.
/// With a simulated plate (`[process.plasma.sim]`) the height is the torch's true one above it;
/// without, it is estimated from the arc voltage against the voltage held.
class CuttingRecorder final : public controller::ControllerObserver, public controller::ReportSection {
 public:
  CuttingRecorder(const machine::PlasmaConfig& plasma, const machine::SimPlasmaConfig& sim, double period_s);
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override;
  CuttingReport report() const;

  std::string report_key() const override { return "cutting"; }
  /// "cutting  … s, height in band … %, deepest dive … mm, … pierces, … arc losses, … holes slowed".
  std::string report_text() const override;
  std::string report_json() const override;

 private:
  machine::PlasmaConfig plasma_;
  std::optional<machine::PlateSurface> plate_;
  double period_s_;
  CuttingReport r_;
  std::uint64_t cutting_ = 0, in_band_ = 0, active_ = 0;
  bool first_ = true;
  std::uint32_t pierces0_ = 0, losses0_ = 0, failed0_ = 0, trips0_ = 0, breakaways0_ = 0;
  std::uint32_t preheats0_ = 0, starts0_ = 0;
  double preheat0_s_ = 0;
  bool hold_before_ = false;
  control::ThcState thc_before_ = control::ThcState::Off;
};

}  // namespace opencnc::cutting
