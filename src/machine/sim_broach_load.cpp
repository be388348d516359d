// SPDX-License-Identifier: GPL-3.0-or-later
// SimBroachLoad: the chip the cutter meets in the bore, and the force and load-cell reading from it.
#include "opencnc/machine/sim_broach_load.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::machine {

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kCellDeg = 360.0 / SimBroachLoad::kAngleCells;
/// mm/s → m/min.
constexpr double kMPerMinPerMmS = 0.06;

}  // namespace

SimBroachLoad::SimBroachLoad(const SimBroachConfig& config, std::uint64_t seed) noexcept
    : config_(config), rng_(seed ^ 0xB20AC4ull), dull_(config.dull_factor) {}

int SimBroachLoad::stroke_cell(double stroke) const noexcept {
  const double length = config_.bore_end - config_.bore_start;
  if (!(length > 0) || stroke < config_.bore_start || stroke >= config_.bore_end) return -1;
  const int cell = static_cast<int>((stroke - config_.bore_start) / length * kStrokeCells);
  return std::clamp(cell, 0, kStrokeCells - 1);
}

int SimBroachLoad::angle_cell(double angle_deg) noexcept {
  double a = std::fmod(angle_deg, 360.0);
  if (a < 0) a += 360.0;
  return std::clamp(static_cast<int>(a / kCellDeg), 0, kAngleCells - 1);
}

double SimBroachLoad::cut_depth(double stroke, double angle_deg) const noexcept {
  const int cell = stroke_cell(stroke);
  if (cell < 0) return 0;
  return cut_[static_cast<std::size_t>(cell * kAngleCells + angle_cell(angle_deg))];
}

bool SimBroachLoad::restore_bore(std::span<const float> bore) noexcept {
  if (bore.size() != cut_.size()) return false;
  std::copy(bore.begin(), bore.end(), cut_.begin());
  cell_ = -1;
  direction_ = 0;
  chip_mm_ = 0;
  return true;
}

// Entering a cell the cutter meets what the strokes before left there (read at the cutter's
// middle) and cuts the wall down to its own depth across its width. Marking the whole width, not
// only the middle, keeps a later stroke along the same helix from finding fresh material in the
// neighbouring angle cell when the workpiece's angle is quantised differently by a count.
void SimBroachLoad::enter_cell(int cell, double angle_deg, double depth) noexcept {
  const std::size_t row = static_cast<std::size_t>(cell) * kAngleCells;
  chip_mm_ = std::max(0.0, depth - cut_[row + static_cast<std::size_t>(angle_cell(angle_deg))]);
  if (depth <= 0) return;
  const double half_deg = 0.5 * config_.width_mm / config_.radius_mm * 180.0 / kPi;
  const int span = static_cast<int>(std::ceil(half_deg / kCellDeg));
  const int middle = angle_cell(angle_deg);
  for (int k = -span; k <= span; ++k) {
    const int a = ((middle + k) % kAngleCells + kAngleCells) % kAngleCells;
    float& d = cut_[row + static_cast<std::size_t>(a)];
    d = std::max(d, static_cast<float>(depth));
  }
}

void SimBroachLoad::update(double stroke, double stroke_velocity, double angle_deg, double radial) noexcept {
  const int cell = stroke_cell(stroke);
  const int direction = stroke_velocity > 0 ? 1 : (stroke_velocity < 0 ? -1 : 0);
  if (cell < 0) {
    chip_mm_ = 0;
  } else if (cell != cell_) {
    enter_cell(cell, angle_deg, radial - config_.surface);
    direction_ = direction;
  } else if (direction != 0 && direction_ != 0 && direction != direction_) {
    chip_mm_ = 0;  // back over what this stroke has just cut
  }
  if (direction != 0 && direction_ == 0) direction_ = direction;  // started from rest in the cell
  cell_ = cell;
  const double speed = std::fabs(stroke_velocity);
  const double force = speed >= config_.min_speed_mm_s && chip_mm_ > 0
                           ? config_.specific_force_n_mm2 * config_.width_mm * chip_mm_ * dull_ *
                                 (1 + config_.speed_gain_per_m_min * speed * kMPerMinPerMmS)
                           : 0.0;
  force_n_ = -direction * force;
  reading_kn_ = force / 1000 + config_.noise_kn * rng_.symmetric();
}

}  // namespace opencnc::machine
