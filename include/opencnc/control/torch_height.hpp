// SPDX-License-Identifier: GPL-3.0-or-later
// TorchHeight — the plasma torch's stage of the tick: each cut's sequence (find the plate, pierce,
// cut height) and the torch height control (arc voltage → a Z offset on top of the programmed
// path, with its limits, speed and acceleration; corner, void and anti-dive locks). Fixed-size
// plain data; nothing allocates (docs/cutting.md).
#pragma once

#include <cstdint>

#include "opencnc/control/torch_status.hpp"
#include "opencnc/machine/plasma.hpp"

namespace opencnc::control {

/// What the tick tells the torch stage each period.
struct TorchInputs {
  bool hold = false;         ///< feed hold, abort or a stop asked: the torch goes out
  double programmed_z = 0;   ///< the torch axis as the interpolator commands it (machine Z)
  double measured_z = 0;     ///< the torch axis' feedback (machine Z), sampled with `sensor`
  double path_velocity = 0;  ///< the path's speed now (mm/s)
  double feed = 0;           ///< the block's programmed feed times the override (0: a rapid or a marker)
  double arc_voltage_v = 0;
  bool arc_ok = false;
  bool sensor = false;     ///< float switch or ohmic contact
  bool breakaway = false;  ///< the torch's breakaway switch (its mount knocked out of place)
  double height_v = 0;     ///< oxy-fuel: the capacitive height sensor's reading (V)
};

/// The torch stage. Servo thread only; every member is real-time safe and allocates nothing.
class TorchHeight {
 public:
  void configure(const machine::PlasmaConfig& config, double period_s) noexcept;
  bool enabled() const noexcept { return config_.enabled != 0; }

  /// A run starts or ends: the torch is off, the offset taken into the commanded position as it
  /// stands (the next run starts from there). Counters are kept, and so is the voltage an
  /// interrupted cut had sampled (for the run that resumes it).
  void begin_run() noexcept;
  /// A run that does not resume an interrupted program starts: its cuts sample their own voltage.
  void forget_interrupted_cut() noexcept { interrupted_target_v_ = 0; }
  /// M190 (torch on: the sequence), M191 (torch off: retract), M192/M193 (hold the height, let
  /// go). False: not one of the torch's codes.
  bool apply_code(int code, double p) noexcept;
  /// A cut chart's setting (machine/cut_chart_codes.hpp: pierce and cut height, pierce delay,
  /// arc voltage, puddle jump) in place of the profile's, until the run ends. False: not one.
  bool apply_chart_code(int code, double p) noexcept;
  /// Oxy-fuel: the operator's start — a preheat under way ends now (cutting oxygen on, pierce).
  /// False: no preheat is under way (nothing changes).
  bool start_cut() noexcept;
  /// One period: the Z offset to add to the programmed path.
  double step(const TorchInputs& in) noexcept;

  /// The interpolator waits (feed and rapids) while the sequence moves the torch up and down.
  bool head_waits() const noexcept { return waits_; }
  /// This period the stage asks the tick to hold the run (arc lost, starts exhausted, no plate).
  bool hold_requested() const noexcept { return hold_request_; }
  /// What to tell (EventKind::Torch): valid while event_pending().
  bool event_pending() const noexcept { return event_pending_; }
  TorchEvent event() const noexcept { return event_; }
  double event_value() const noexcept { return event_value_; }
  bool torch_on() const noexcept { return status_.torch_on; }
  double offset_mm() const noexcept { return offset_; }
  const TorchStatus& status() const noexcept { return status_; }
  const machine::PlasmaConfig& config() const noexcept { return config_; }

 private:
  void enter(TorchPhase p) noexcept;
  void tell(TorchEvent e, double value, bool hold) noexcept;
  bool arc_lost(const TorchInputs& in) noexcept;
  bool knocked(const TorchInputs& in) noexcept;
  bool move_to(double target) noexcept;  // true once there and at rest
  void probe(const TorchInputs& in) noexcept;
  void ignite(const TorchInputs& in) noexcept;
  void ignite_flame() noexcept;
  void preheat() noexcept;
  void filter(const TorchInputs& in) noexcept;
  double height_error_mm() const noexcept;  // + : too high
  bool jumped() const noexcept;             // the signal far off its target (a kerf, a void, an edge)
  void cut(const TorchInputs& in) noexcept;
  ThcState thc_state(const TorchInputs& in) noexcept;
  void correct(const TorchInputs& in, ThcState s) noexcept;
  double offset_for_height(double height_mm) const noexcept {
    return status_.plate_z_mm + height_mm - programmed_z_;
  }

  machine::PlasmaConfig config_{};
  machine::PlasmaConfig profile_{};  ///< as configured: each run starts from it (a chart's values last a run)
  double dt_ = 1e-3;
  TorchStatus status_{};
  bool programmed_on_ = false;  ///< between M190 and M191
  bool waits_ = false, hold_request_ = false, event_pending_ = false;
  TorchEvent event_ = TorchEvent::ArcLost;
  double event_value_ = 0;
  bool paused_held_ = false;  ///< Paused or Failed: the hold has been seen (a resume follows it)
  double retract_target_ = 0;
  double offset_ = 0, v_ = 0;  ///< the Z offset and its speed
  double programmed_z_ = 0;
  double timer_s_ = 0;  ///< time in the phase (or since the arc went off while cutting)
  double arc_off_s_ = 0;
  int starts_failed_ = 0;
  double cut_offset_ = 0;  ///< the offset at the cut height (the correction's origin)
  bool filter_primed_ = false;
  double since_cut_s_ = 0;  ///< at the cut height this long
  double sample_sum_ = 0, sample_s_ = 0;
  double void_timer_s_ = 0;
  double last_velocity_ = 0, decel_ = 0;
  /// The auto-volts target of a cut that was interrupted (arc lost, knocked, feed hold): the cut
  /// that goes on from there — pierced again where it held, or at a retrace's C over the kerf it
  /// had already cut — keeps it instead of sampling over that kerf. 0: none.
  double interrupted_target_v_ = 0;
  bool start_asked_ = false;      ///< the operator's start, for the preheat under way
  bool sensor_in_range_ = false;  ///< oxy-fuel: the height sensor's reading is within its range
};

}  // namespace opencnc::control
