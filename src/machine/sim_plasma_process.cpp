// SPDX-License-Identifier: GPL-3.0-or-later
// SimPlasmaProcess: the simulated plate, arc and torch sensors (machine/sim_plasma_process.hpp).
#include "opencnc/machine/sim_plasma_process.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace opencnc::machine {

PlateSurface::PlateSurface(const SimPlasmaConfig& config) noexcept
    : mean_(config.plate_z_mm), amplitude_(config.warp_mm) {
  SplitMix64 rng(config.seed ^ 0x5eed'91a7'e000'0001ull);
  constexpr double kScale[3] = {1.0, 1.7, 2.9};
  for (std::size_t i = 0; i < 3; ++i) {
    const double angle = std::numbers::pi * rng.symmetric();
    const double k = 2 * std::numbers::pi / (config.warp_wavelength_mm * kScale[i]);
    kx_[i] = k * std::cos(angle);
    ky_[i] = k * std::sin(angle);
    phase_[i] = std::numbers::pi * rng.symmetric();
  }
}

double PlateSurface::z(double x, double y) const noexcept {
  double s = 0;
  for (std::size_t i = 0; i < 3; ++i) s += std::sin(kx_[i] * x + ky_[i] * y + phase_[i]);
  return mean_ + amplitude_ * s / 3;
}

void SimPlasmaProcess::configure(const SimPlasmaConfig& config, double period_s) {
  config_ = config;
  surface_ = PlateSurface(config);
  period_s_ = period_s;
  rng_ = SplitMix64(config.seed ^ 0xa5c0'0000'0000'0002ull);
  cell_mm_ = std::max(0.05, config.kerf_width_mm / 3);
  columns_ = std::max(1L, std::lround((config.plate_max[0] - config.plate_min[0]) / cell_mm_) + 1);
  rows_ = std::max(1L, std::lround((config.plate_max[1] - config.plate_min[1]) / cell_mm_) + 1);
  kerf_.assign(static_cast<std::size_t>((columns_ * rows_ + 63) / 64), 0);
  trail_first_ = trail_count_ = 0;
  moved_once_ = false;
}

bool SimPlasmaProcess::cell(double x, double y, std::size_t& index) const noexcept {
  const long c = std::lround((x - config_.plate_min[0]) / cell_mm_);
  const long r = std::lround((y - config_.plate_min[1]) / cell_mm_);
  if (c < 0 || r < 0 || c >= columns_ || r >= rows_) return false;
  index = static_cast<std::size_t>(r * columns_ + c);
  return true;
}

bool SimPlasmaProcess::kerf_at(double x, double y) const noexcept {
  std::size_t i = 0;
  return cell(x, y, i) && ((kerf_[i / 64] >> (i % 64)) & 1u) != 0;
}

// The kerf's disc around `p`: every cell within half the kerf's width.
void SimPlasmaProcess::mark(const Point& p) noexcept {
  const double r = config_.kerf_width_mm / 2;
  const long n = static_cast<long>(std::ceil(r / cell_mm_));
  for (long dr = -n; dr <= n; ++dr) {
    for (long dc = -n; dc <= n; ++dc) {
      const double dx = static_cast<double>(dc) * cell_mm_, dy = static_cast<double>(dr) * cell_mm_;
      if (dx * dx + dy * dy > r * r) continue;
      std::size_t i = 0;
      if (cell(p.x + dx, p.y + dy, i)) kerf_[i / 64] |= std::uint64_t{1} << (i % 64);
    }
  }
}

void SimPlasmaProcess::flush_trail() noexcept {
  for (; trail_count_ > 0; --trail_count_, trail_first_ = (trail_first_ + 1) % kTrail)
    mark(trail_[static_cast<std::size_t>(trail_first_)]);
}

void SimPlasmaProcess::lose_arc() noexcept {
  arc_ = false;
  blocked_ = true;  // until the torch is switched off and on again
  ++losses_;
  flush_trail();
}

void SimPlasmaProcess::step(double x, double y, double z, bool torch_on, bool cut_oxygen) noexcept {
  const Point p{x, y};
  speed_ = moved_once_ ? std::hypot(x - last_.x, y - last_.y) / period_s_ : 0.0;
  last_ = p;
  moved_once_ = true;
  z_ = z;
  plate_ = surface_.z(x, y);
  height_ = z - plate_;
  torch_on_ = torch_on;
  on_plate_ = x >= config_.plate_min[0] && x <= config_.plate_max[0] && y >= config_.plate_min[1] &&
              y <= config_.plate_max[1];
  if (config_.oxy_fuel) {  // no arc: the cutting oxygen cuts the kerf while the flame burns
    if (arc_ && !(torch_on && cut_oxygen)) flush_trail();
    arc_ = torch_on && cut_oxygen;
    blocked_ = false;
  } else if (!torch_on) {
    if (arc_) flush_trail();
    arc_ = blocked_ = false;
    transfer_s_ = 0;
  } else if (!arc_ && !blocked_) {
    // The pilot arc transfers to the plate from close enough, after the arc delay.
    transfer_s_ = height_ <= config_.transfer_height_mm ? transfer_s_ + period_s_ : 0.0;
    arc_ = transfer_s_ >= config_.arc_delay_s - 1e-12;
  } else if (arc_) {
    const double p_loss = config_.arc_losses_per_min / 60 * period_s_;
    const bool random_loss = p_loss > 0 && 0.5 * (rng_.symmetric() + 1) < p_loss;
    if (loss_pending_ || random_loss || height_ > config_.max_arc_height_mm) {
      loss_pending_ = false;
      lose_arc();
    }
  }
  if (config_.oxy_fuel) over_kerf_ = kerf_at(x, y);  // the sensor sees a kerf with the oxygen off too
  if (arc_) {
    over_kerf_ = kerf_at(x, y);
    // The kerf behind the torch: marked once the torch is a kerf's width past it.
    const double spacing = config_.kerf_width_mm / 6;
    const Point& newest =
        trail_[static_cast<std::size_t>((trail_first_ + trail_count_ - 1 + kTrail) % kTrail)];
    if (trail_count_ == 0 || std::hypot(x - newest.x, y - newest.y) >= spacing) {
      if (trail_count_ == kTrail) {
        mark(trail_[static_cast<std::size_t>(trail_first_)]);
        trail_first_ = (trail_first_ + 1) % kTrail;
        --trail_count_;
      }
      trail_[static_cast<std::size_t>((trail_first_ + trail_count_) % kTrail)] = p;
      ++trail_count_;
    }
    while (trail_count_ > 0) {
      const Point& oldest = trail_[static_cast<std::size_t>(trail_first_)];
      if (std::hypot(x - oldest.x, y - oldest.y) < config_.kerf_width_mm * 1.5) break;
      mark(oldest);
      trail_first_ = (trail_first_ + 1) % kTrail;
      --trail_count_;
    }
    const double slow = 1 - std::min(speed_ / config_.full_speed_mm_s, 1.0);
    voltage_ = config_.oxy_fuel ? 0.0
                                : config_.base_voltage_v + config_.volts_per_mm * height_ +
                                      config_.slow_volts_v * slow + (over_kerf_ ? config_.kerf_volts_v : 0.0);
  } else {
    if (!config_.oxy_fuel) over_kerf_ = false;
    voltage_ = 0;
  }
}

double SimPlasmaProcess::sensed_height_mm() const noexcept {
  if (!on_plate_) return config_.sensor_range_mm;
  return std::min(height_ + (over_kerf_ ? config_.kerf_height_mm : 0.0), config_.sensor_range_mm);
}

void SimPlasmaProcess::sample(MachineInputs& in) noexcept {
  if (config_.oxy_fuel) {
    const double sensed = sensed_height_mm(), noise = config_.height_noise_mm * rng_.symmetric();
    // Nothing under the ring: the amplifier stands at its end of range, noise or not.
    const double h =
        sensed >= config_.sensor_range_mm ? sensed : std::min(sensed + noise, config_.sensor_range_mm);
    in.analog_in[static_cast<std::size_t>(config_.height_input)] =
        config_.sensor_zero_v + config_.sensor_volts_per_mm * std::max(h, 0.0);
    return;
  }
  in.process.arc_ok = arc_;
  const double noise = config_.noise_v * rng_.symmetric();
  in.analog_in[static_cast<std::size_t>(config_.arc_voltage_input)] = arc_ ? voltage_ + noise : 0.0;
  const double trip = config_.sensor == PlateSensor::Float ? plate_ - config_.switch_offset_mm : plate_;
  const bool touching = z_ <= trip + config_.sensor_noise_mm * rng_.symmetric();
  const std::uint64_t bit = std::uint64_t{1} << config_.sensor_input;
  in.digital_in = touching ? (in.digital_in | bit) : (in.digital_in & ~bit);
}

}  // namespace opencnc::machine
