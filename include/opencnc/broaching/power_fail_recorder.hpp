// SPDX-License-Identifier: GPL-3.0-or-later
// PowerFailRecorder — what a power-fail stop did to a coupled helix: the largest helix error of
// the coupled stop (feedback and command), the same stop simulated with each axis braking on its
// own at its limits, the stop's time and distance and the lowest DC link (`opencnc run --inject`).
#pragma once

#include <optional>
#include <vector>

#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/motion/coupling.hpp"
#include "opencnc/plan/machine_limits.hpp"

namespace opencnc::broaching {

/// The figures of one power-fail stop (valid once `stopped`).
struct PowerFailReport {
  bool happened = false;        ///< the servo began a power-fail stop during the run
  bool coupled = false;         ///< a coupling law held when it began
  double signal_s = 0;          ///< servo time of the stop's first period
  double stop_time_s = 0;       ///< from the signal until the commanded master was at rest
  double stop_distance_mm = 0;  ///< of the master, commanded
  /// Largest helix error during the stop: C's angle against the law at Z, times the radius (µm);
  /// of the feedback (what the groove sees) and of the command (the coupling itself).
  double coupled_error_um = 0;
  double coupled_command_error_um = 0;
  /// The same stop with each axis braking on its own at its acceleration limit from the
  /// commanded state at the signal (no coupling): the largest helix error, µm.
  double independent_error_um = 0;
  double dc_link_min_v = 0;  ///< lowest DC link voltage seen from the signal on
  /// The link's usable energy above its minimum voltage (profile's [power]; 0 when not stated), J:
  /// in the period of the signal and in the last period the master moved.
  double energy_at_signal_j = 0;
  double energy_at_rest_j = 0;
  double decel_scale = 1;  ///< the stop's deceleration, times the path's budget (1: as planned)
};

/// An observer (trace and status every period) of a run that may meet a power failure.
/// Controller thread; non-real-time.
class PowerFailRecorder final : public controller::ControllerObserver, public controller::ReportSection {
 public:
  /// `coupling`: the machine's (its tables); `limits`: the planner's (the independent stop brakes
  /// at them); `radius_mm`: where the helix error is measured (the bore's radius).
  PowerFailRecorder(const motion::CouplingConfig& coupling, const plan::MachineLimits& limits,
                    double period_s, double radius_mm);

  void on_status(const controller::ControllerStatus& s) override;
  void on_trace(const control::TraceSample& s, const controller::TraceContext& c) override;
  PowerFailReport report() const { return report_; }

  std::string report_key() const override { return "power_fail"; }
  /// "power fail at … s: stopped in … s over … mm, DC link down to … V" (or "none"), the DC link's
  /// energy and, coupled, the helix error.
  std::string report_text() const override;
  /// The report's values by their names (`happened`, `coupled`, `signal_s`, …).
  std::string report_json() const override;

 private:
  motion::CouplingLaw law_of(const control::CouplingStatus& c) const;
  double helix_error_um(double master, double slave) const;
  void simulate_independent_stop(const control::TraceSample& before, const control::TraceSample& at);

  motion::CouplingConfig coupling_;
  plan::MachineLimits limits_;
  double period_s_, radius_mm_;
  control::CouplingStatus status_{};  ///< the coupling of the last coupled status
  motion::CouplingLaw law_{};
  std::optional<control::TraceSample> previous_;
  bool stopping_ = false;
  double master_at_signal_ = 0;
  PowerFailReport report_;
};

}  // namespace opencnc::broaching
