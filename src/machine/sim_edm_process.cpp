// SPDX-License-Identifier: GPL-3.0-or-later
// SimEdmProcess: the spark gap, period by period (the model and its constants: docs/edm.md).
#include "opencnc/machine/sim_edm_process.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::machine {

namespace {

/// Close to a standard normal sample: the sum of three uniforms in [-1, 1) has variance 1.
double gauss(SplitMix64& rng) noexcept {
  return rng.symmetric() + rng.symmetric() + rng.symmetric();
}

/// The widest gap the electrode stays clear of the debris at: lifted this far, the flow flushes.
constexpr double kClearGaps = 3;
/// An arc removes this share of what a normal discharge does (and burns one spot).
constexpr double kArcRemoval = 0.1;

}  // namespace

void SimEdmProcess::configure(const SimEdmConfig& config, double period_s) noexcept {
  config_ = config;
  period_s_ = period_s;
  fronts_ = 0;
}

int SimEdmProcess::front_for(const double orientation[2]) noexcept {
  std::int32_t k[2];
  for (int i = 0; i < 2; ++i) k[i] = static_cast<std::int32_t>(std::lround(orientation[i]));
  for (int f = 0; f < fronts_; ++f)
    if (key_[static_cast<std::size_t>(2 * f)] == k[0] && key_[static_cast<std::size_t>(2 * f + 1)] == k[1])
      return f;
  const int f = fronts_ < kMaxFronts ? fronts_++ : kMaxFronts - 1;  // beyond eight: the last one again
  key_[static_cast<std::size_t>(2 * f)] = k[0];
  key_[static_cast<std::size_t>(2 * f + 1)] = k[1];
  front_[static_cast<std::size_t>(f)] = config_.surface_mm;
  return f;
}

double SimEdmProcess::depth_mm() const noexcept {
  if (fronts_ == 0) return 0;
  return (front_[static_cast<std::size_t>(front_index_)] - config_.surface_mm) * config_.work_direction;
}

void SimEdmProcess::step(double electrode, const double orientation[2], bool generator_on,
                         const GeneratorOutputs& gen, SplitMix64& rng) noexcept {
  front_index_ = front_for(orientation);
  const double front = front_[static_cast<std::size_t>(front_index_)];
  gap_mm_ = (electrode - front) * -config_.work_direction;
  const double u0 = gen.voltage_v;
  const double breakdown = config_.breakdown_um_per_v * 1e-3 * u0 * (1 + debris_);
  // The dielectric flushes the debris slowly; fast once a jump has lifted the electrode clear.
  const bool clear = !generator_on && gap_mm_ > kClearGaps * std::max(breakdown, 0.01);
  const double tau = clear ? config_.jump_flush_time_s : config_.flush_time_s;
  debris_ -= debris_ * std::min(1.0, period_s_ / tau);
  if (short_pending_ && generator_on) {  // a bridge forms where it sparks
    short_pending_ = false;
    short_ = true;
    bridge_until_mm_ = gap_mm_ + config_.short_bridge_mm;
  }
  if (short_ && gap_mm_ > bridge_until_mm_) short_ = false;
  if (!generator_on || u0 <= 0) {
    state_ = GapState::Open;
    voltage_v_ = 0;
    return;
  }
  if (short_ || gap_mm_ <= 0) {
    state_ = GapState::Short;
    voltage_v_ = 0.5 + 0.2 * std::fabs(gauss(rng));
  } else if (gap_mm_ >= breakdown) {
    state_ = GapState::Open;
    voltage_v_ = u0 + config_.noise_v * gauss(rng);
  } else {
    discharge(gen, gap_mm_ / breakdown, rng);
  }
}

// The discharges of one period: each waits an ignition delay that grows without bound as the gap
// nears the breakdown width (t_d = t_on·x/(1−x), x = gap / breakdown gap), burns for t_on at the
// discharge voltage and pauses t_off; the mean voltage is (U0·t_d + Ue·t_on)/(t_d + t_on + t_off).
// Debris above the threshold turns discharges into arcs (no delay, little removal) with a
// probability that grows with it.
void SimEdmProcess::discharge(const GeneratorOutputs& gen, double x, SplitMix64& rng) noexcept {
  const double ton = std::max(gen.on_time_us, 0.1), toff = std::max(gen.off_time_us, 0.0);
  const double ue = config_.discharge_voltage_v;
  const double p_arc = std::clamp((debris_ - config_.arc_threshold) / (1 - config_.arc_threshold), 0.0, 1.0);
  const bool arc = p_arc > 0 && 0.5 * (rng.symmetric() + 1) < p_arc;
  const double td = arc ? 0.0 : ton * x / (1 - x);
  const double cycle_us = td + ton + toff;
  state_ = arc ? GapState::Arc : GapState::Normal;
  voltage_v_ = (gen.voltage_v * td + ue * ton) / cycle_us + config_.noise_v * gauss(rng);
  const double n = period_s_ * 1e6 / cycle_us;
  const double volume =
      n * config_.removal_mm3_per_a_us * gen.peak_current_a * ton * (arc ? kArcRemoval : 1.0);
  const double dz = std::min(volume / config_.electrode_area_mm2, gap_mm_);
  front_[static_cast<std::size_t>(front_index_)] += config_.work_direction * dz;
  gap_mm_ -= dz;
  debris_ = std::min(2.0, debris_ + volume * config_.debris_per_mm3);
  discharges_ += static_cast<std::uint64_t>(n);
}

void SimEdmProcess::sample(ProcessInputs& in) const noexcept {
  in.gap_voltage_v = std::max(0.0, voltage_v_);
  in.gap_state = state_;
}

}  // namespace opencnc::machine
