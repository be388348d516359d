// SPDX-License-Identifier: GPL-3.0-or-later
// TorchHeight: the sequence of a plasma cut and its torch height control, one period at a time
// (control/torch_height.hpp, docs/cutting.md).
#include "opencnc/control/torch_height.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::control {

using machine::PlateSensor;

void TorchHeight::configure(const machine::PlasmaConfig& config, double period_s) noexcept {
  config_ = profile_ = config;
  dt_ = period_s;
  status_ = TorchStatus{};
  interrupted_target_v_ = 0;
  status_.oxy_fuel = config.oxy_fuel();
  begin_run();
}

void TorchHeight::begin_run() noexcept {
  config_ = profile_;
  programmed_on_ = false;
  waits_ = hold_request_ = event_pending_ = false;
  offset_ = v_ = 0;
  starts_failed_ = 0;
  start_asked_ = false;
  status_.thc_hold = false;
  status_.torch_on = false;
  status_.cut_oxygen = status_.waiting_start = false;
  enter(TorchPhase::Off);
  status_.thc_offset_mm = status_.correction_mm = 0;
}

bool TorchHeight::apply_code(int code, double p) noexcept {
  switch (code) {
    case machine::kTorchOnCode:
      programmed_on_ = true;
      starts_failed_ = 0;
      enter(TorchPhase::Probing);
      return true;
    case machine::kTorchOffCode:
      programmed_on_ = false;
      interrupted_target_v_ = 0;  // the cut has ended as programmed
      status_.torch_on = false;
      retract_target_ = std::max(offset_, 0.0);  // up to the programmed height, never down
      enter(TorchPhase::Retracting);
      return true;
    case machine::kThcHoldCode:
      status_.thc_hold = true;
      return true;
    case machine::kThcReleaseCode:
      status_.thc_hold = false;
      return true;
    default:
      return apply_chart_code(code, p);
  }
}

void TorchHeight::enter(TorchPhase p) noexcept {
  // A cut that stops burning before its M191 keeps what it had sampled for the cut that goes on.
  if (status_.phase == TorchPhase::Cutting && p != TorchPhase::Retracting && config_.arc_voltage_v <= 0 &&
      status_.target_voltage_v > 0)
    interrupted_target_v_ = status_.target_voltage_v;
  status_.phase = p;
  status_.thc = ThcState::Off;
  timer_s_ = 0;
  arc_off_s_ = 0;
  paused_held_ = false;
}

void TorchHeight::tell(TorchEvent e, double value, bool hold) noexcept {
  event_pending_ = true;
  event_ = e;
  event_value_ = value;
  hold_request_ = hold_request_ || hold;
}

// The offset toward `target` at the height moves' speed and acceleration: the fastest speed that
// can still stop at the target with steps of a·T (and never more than the rest in one period).
bool TorchHeight::move_to(double target) noexcept {
  const double a = config_.height_accel_mm_s2, ad = a * dt_;
  const double d = target - offset_;
  const double brake = -0.5 * ad + std::sqrt(0.25 * ad * ad + 2 * a * std::fabs(d));
  const double vd = std::copysign(std::min({config_.height_speed_mm_s, brake, std::fabs(d) / dt_}), d);
  v_ += std::clamp(vd - v_, -ad, ad);
  offset_ += v_ * dt_;
  if (std::fabs(target - offset_) < 1e-9 && std::fabs(v_) <= ad) {
    offset_ = target;
    v_ = 0;
    return true;
  }
  return false;
}

// Arc-OK off for longer than arc_loss_s once the arc was there: torch off, the run held.
bool TorchHeight::arc_lost(const TorchInputs& in) noexcept {
  if (config_.oxy_fuel()) return false;  // a flame has no arc-OK (no flame-out input: docs/cutting.md)
  arc_off_s_ = in.arc_ok ? 0.0 : arc_off_s_ + dt_;
  if (arc_off_s_ < config_.arc_loss_s || arc_off_s_ == 0) return false;
  ++status_.arc_losses;
  status_.torch_on = false;
  tell(TorchEvent::ArcLost, status_.thc_offset_mm, true);
  enter(TorchPhase::Paused);
  return true;
}

// The breakaway switch in any phase of a cut, or the float switch once the torch burns (pressed
// down: it touched the plate): torch off, the run held. A resume finds the plate and pierces
// again where the torch stands (knocked again at once while the breakaway switch stays open).
bool TorchHeight::knocked(const TorchInputs& in) noexcept {
  const TorchPhase p = status_.phase;
  const bool burning = p == TorchPhase::Piercing || p == TorchPhase::Puddle || p == TorchPhase::ToCut ||
                       p == TorchPhase::Cutting;
  const bool floated = burning && in.sensor && config_.sensor == PlateSensor::Float && !config_.oxy_fuel();
  if (!in.breakaway && !floated) return false;
  status_.torch_on = false;
  ++(in.breakaway ? status_.breakaways : status_.float_trips);
  tell(in.breakaway ? TorchEvent::Breakaway : TorchEvent::FloatTripped, status_.thc_offset_mm, true);
  enter(TorchPhase::Paused);
  return true;
}

double TorchHeight::step(const TorchInputs& in) noexcept {
  hold_request_ = event_pending_ = false;
  programmed_z_ = in.programmed_z;
  status_.arc_voltage_v = in.arc_voltage_v;
  status_.arc_ok = in.arc_ok;
  status_.sensor = in.sensor;
  filter(in);
  timer_s_ += dt_;
  const TorchPhase p = status_.phase;
  const bool sequencing = p == TorchPhase::Probing || p == TorchPhase::ToPierce ||
                          p == TorchPhase::Igniting || p == TorchPhase::Piercing || p == TorchPhase::Puddle ||
                          p == TorchPhase::ToCut || p == TorchPhase::Cutting || p == TorchPhase::Preheating;
  if (in.hold && sequencing) {  // a feed hold puts the torch out; a resume pierces again here
    status_.torch_on = false;
    enter(TorchPhase::Paused);
  } else if (sequencing) {
    knocked(in);
  }
  waits_ = false;
  switch (status_.phase) {
    case TorchPhase::Off:
      move_to(offset_);  // at rest where it is (the offset is 0 after a retract)
      break;
    case TorchPhase::Probing:
      waits_ = true;
      probe(in);
      break;
    case TorchPhase::ToPierce:
      waits_ = true;
      if (move_to(
              offset_for_height(config_.oxy_fuel() ? config_.preheat_height_mm : config_.pierce_height_mm))) {
        status_.torch_on = true;
        enter(TorchPhase::Igniting);
      }
      break;
    case TorchPhase::Igniting:
      waits_ = true;
      if (config_.oxy_fuel())
        ignite_flame();
      else
        ignite(in);
      break;
    case TorchPhase::Preheating:
      waits_ = true;
      preheat();
      break;
    case TorchPhase::Piercing:
      waits_ = true;
      // Oxy-fuel rises from the preheat to the pierce height with the cutting oxygen on (the slag
      // blows up out of the hole); plasma pierces where it stands.
      move_to(config_.oxy_fuel() ? offset_for_height(config_.pierce_height_mm) : offset_);
      if (arc_lost(in)) break;
      if (timer_s_ >= config_.pierce_delay_s - 1e-12)
        enter(config_.puddle_height_mm > 0 ? TorchPhase::Puddle : TorchPhase::ToCut);
      break;
    case TorchPhase::Puddle:
      move_to(offset_for_height(config_.puddle_height_mm));
      if (arc_lost(in)) break;
      if (timer_s_ >= config_.puddle_delay_s - 1e-12) enter(TorchPhase::ToCut);
      break;
    case TorchPhase::ToCut:
      waits_ = config_.puddle_height_mm <= 0;  // after a puddle jump the path moves on meanwhile
      if (arc_lost(in)) break;
      if (move_to(offset_for_height(config_.cut_height_mm))) {
        cut_offset_ = offset_;
        status_.cut_z_mm = status_.plate_z_mm + config_.cut_height_mm;
        since_cut_s_ = sample_sum_ = sample_s_ = void_timer_s_ = 0;
        if (config_.oxy_fuel())
          status_.target_voltage_v = 0;  // the height sensor reads the height itself
        else
          status_.target_voltage_v = config_.arc_voltage_v > 0 ? config_.arc_voltage_v : interrupted_target_v_;
        interrupted_target_v_ = 0;
        last_velocity_ = in.path_velocity;
        enter(TorchPhase::Cutting);
        waits_ = false;  // the path goes on in this very period
      }
      break;
    case TorchPhase::Cutting:
      if (arc_lost(in)) break;
      cut(in);
      break;
    case TorchPhase::Retracting:
      waits_ = true;
      status_.torch_on = false;
      if (move_to(retract_target_)) enter(TorchPhase::Off);
      break;
    case TorchPhase::Paused:
    case TorchPhase::Failed:
      status_.torch_on = false;
      move_to(offset_);
      if (in.hold) {
        paused_held_ = true;
      } else if (paused_held_) {  // resumed: find the plate again and pierce where the torch stands
        starts_failed_ = 0;
        enter(programmed_on_ ? TorchPhase::Probing : TorchPhase::Retracting);
      }
      break;
  }
  status_.thc_offset_mm = offset_;
  status_.correction_mm = status_.phase == TorchPhase::Cutting ? offset_ - cut_offset_ : 0.0;
  const TorchPhase q = status_.phase;
  status_.cut_oxygen = config_.oxy_fuel() && status_.torch_on &&
                       (q == TorchPhase::Piercing || q == TorchPhase::ToCut || q == TorchPhase::Cutting);
  status_.waiting_start = q == TorchPhase::Preheating && config_.preheat == machine::PreheatMode::Operator;
  return offset_;
}

// The signal the height control holds: the arc voltage (plasma, while the arc burns) or the
// height the capacitive sensor reads (oxy-fuel, always: it needs no flame), each through the
// same first-order low-pass filter.
void TorchHeight::filter(const TorchInputs& in) noexcept {
  const double k = filter_primed_ ? dt_ / (config_.filter_s + dt_) : 1.0;
  if (config_.oxy_fuel()) {
    const double h = (in.height_v - config_.sensor_zero_v) / config_.sensor_volts_per_mm;
    sensor_in_range_ = h < config_.sensor_range_mm;
    status_.sensor = sensor_in_range_;
    status_.sensor_height_mm += k * (std::min(h, config_.sensor_range_mm) - status_.sensor_height_mm);
    filter_primed_ = true;
    return;
  }
  if (status_.torch_on && in.arc_ok) {
    status_.filtered_voltage_v += k * (in.arc_voltage_v - status_.filtered_voltage_v);
    filter_primed_ = true;
  } else {
    filter_primed_ = false;
  }
}

// Oxy-fuel: the flame lights in ignite_s (no arc-OK to wait for), then the preheat begins.
void TorchHeight::ignite_flame() noexcept {
  move_to(offset_);
  status_.torch_on = true;
  if (timer_s_ < config_.ignite_s - 1e-12) return;
  ++status_.preheats;
  status_.preheat_s = 0;
  start_asked_ = false;
  enter(TorchPhase::Preheating);
  if (config_.preheat == machine::PreheatMode::Operator) tell(TorchEvent::PreheatWaits, 0, false);
}

// The flame heats the plate where the torch stands until the time is up (by time) or the
// operator starts the cut (either way); then the cutting oxygen goes on and the pierce begins.
void TorchHeight::preheat() noexcept {
  move_to(offset_);
  status_.preheat_s += dt_;
  status_.preheat_total_s += dt_;
  const bool timed_out =
      config_.preheat == machine::PreheatMode::Time && status_.preheat_s >= config_.preheat_s - 1e-12;
  if (!timed_out && !start_asked_) return;
  if (start_asked_) ++status_.operator_starts;
  start_asked_ = false;
  ++status_.pierces;
  tell(TorchEvent::CutStarted, status_.preheat_s, false);
  enter(TorchPhase::Piercing);
}

bool TorchHeight::start_cut() noexcept {
  if (status_.phase != TorchPhase::Preheating) return false;
  start_asked_ = true;
  return true;
}

double TorchHeight::height_error_mm() const noexcept {
  if (config_.oxy_fuel()) return status_.sensor_height_mm - config_.cut_height_mm;
  return (status_.filtered_voltage_v - status_.target_voltage_v) / config_.volts_per_mm;
}

// Oxy-fuel: only a reading that says the torch is higher than it is (a kerf or a hole under the
// ring: less steel) or out of range (the plate's edge) holds; following it would dive. A reading
// far below the cut height is followed up — the plate nearer than the cut height, whether it rose
// or was found low (sensed over a kerf already cut: a retrace's C) — which never dives.
bool TorchHeight::jumped() const noexcept {
  if (config_.oxy_fuel()) return !sensor_in_range_ || height_error_mm() > config_.height_jump_mm;
  return std::fabs(status_.filtered_voltage_v - status_.target_voltage_v) > config_.void_jump_v;
}

// Down at the probe speed until the switch; the plate's top is where the torch stood when the
// input was sampled, plus the float's travel. The torch brakes on toward the pierce height.
void TorchHeight::probe(const TorchInputs& in) noexcept {
  if (config_.oxy_fuel() && sensor_in_range_) {  // the capacitive sensor reads the height itself
    // This period's reading, unfiltered: the filter lags the probe's motion by its time constant.
    const double h = (in.height_v - config_.sensor_zero_v) / config_.sensor_volts_per_mm;
    status_.plate_z_mm = in.measured_z - h;
    enter(TorchPhase::ToPierce);
    move_to(offset_for_height(config_.preheat_height_mm));
    return;
  }
  if (in.sensor && !config_.oxy_fuel()) {
    status_.plate_z_mm =
        in.measured_z + (config_.sensor == PlateSensor::Float ? config_.switch_offset_mm : 0.0);
    enter(TorchPhase::ToPierce);
    move_to(offset_for_height(config_.pierce_height_mm));  // braking in this period already
    return;
  }
  if (offset_ <= -config_.probe_travel_mm) {
    tell(TorchEvent::PlateNotFound, offset_, true);
    enter(TorchPhase::Failed);
    return;
  }
  const double ad = config_.height_accel_mm_s2 * dt_;
  v_ = std::max(v_ - ad, -config_.probe_speed_mm_s);
  if (v_ > 0) v_ = std::max(0.0, v_ - 2 * ad);
  offset_ = std::max(offset_ + v_ * dt_, -config_.probe_travel_mm);
}

// Torch on until arc-OK; a start that times out is tried again, up to max_starts in a row.
void TorchHeight::ignite(const TorchInputs& in) noexcept {
  move_to(offset_);
  if (in.arc_ok && status_.torch_on) {
    ++status_.pierces;
    starts_failed_ = 0;
    enter(TorchPhase::Piercing);
    return;
  }
  status_.torch_on = true;
  if (timer_s_ < config_.arc_ok_timeout_s) return;
  ++status_.failed_starts;
  ++starts_failed_;
  status_.torch_on = false;  // off for this period, then on again
  if (starts_failed_ >= config_.max_starts) {
    tell(TorchEvent::StartsExhausted, starts_failed_, true);
    enter(TorchPhase::Failed);
    return;
  }
  tell(TorchEvent::StartFailed, starts_failed_, false);
  enter(TorchPhase::Igniting);
}

// At the cut height: the height control's state, then the correction it allows.
void TorchHeight::cut(const TorchInputs& in) noexcept {
  since_cut_s_ += dt_;
  const ThcState s = thc_state(in);
  status_.thc = s;
  correct(in, s);
}

ThcState TorchHeight::thc_state(const TorchInputs& in) noexcept {
  const double braking = (last_velocity_ - in.path_velocity) / dt_;
  last_velocity_ = in.path_velocity;
  if (config_.thc == 0) return ThcState::Off;
  if (void_timer_s_ > 0) void_timer_s_ = std::max(0.0, void_timer_s_ - dt_);
  const bool known = config_.oxy_fuel() || status_.target_voltage_v > 0;
  if (status_.thc_hold) return ThcState::ProgramLock;
  const bool at_speed = in.feed > 0 && in.path_velocity >= config_.speed_share * in.feed;
  if (!at_speed) return known ? ThcState::CornerLock : ThcState::Waiting;
  if (braking > config_.anti_dive_mm_s2) return ThcState::AntiDive;
  if (since_cut_s_ < config_.thc_delay_s) return ThcState::Waiting;
  if (!known) {  // auto volts: the mean of the filtered voltage over the sample's length
    sample_sum_ += status_.filtered_voltage_v * dt_;
    sample_s_ += dt_;
    if (sample_s_ >= config_.sample_s - 1e-12) status_.target_voltage_v = sample_sum_ / sample_s_;
    return ThcState::Sampling;
  }
  if (jumped()) void_timer_s_ = config_.void_hold_s;
  return void_timer_s_ > 0 ? ThcState::VoidLock : ThcState::Active;
}

// Active: a speed toward the height the voltage (or the height sensor) says is right, e/τ, within the
// deadband none; locked: none. The speed is reached at the correction's acceleration, and the correction
// stays within ±max_correction_mm of the cut height found by the probe.
void TorchHeight::correct(const TorchInputs& /*in*/, ThcState s) noexcept {
  double want = 0;
  if (s == ThcState::Active) {
    const double error_mm = height_error_mm();
    const bool outside =
        config_.oxy_fuel()
            ? std::fabs(error_mm) > config_.deadband_mm
            : std::fabs(status_.filtered_voltage_v - status_.target_voltage_v) > config_.deadband_v;
    if (outside)
      want = std::clamp(-error_mm / config_.time_constant_s, -config_.max_velocity_mm_s,
                        config_.max_velocity_mm_s);
  }
  const double ad = config_.max_accel_mm_s2 * dt_;
  v_ += std::clamp(want - v_, -ad, ad);
  offset_ += v_ * dt_;
  const double lo = cut_offset_ - config_.max_correction_mm, hi = cut_offset_ + config_.max_correction_mm;
  if (offset_ < lo || offset_ > hi) {
    offset_ = std::clamp(offset_, lo, hi);
    v_ = 0;
  }
}

}  // namespace opencnc::control
