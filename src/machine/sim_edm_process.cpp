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
  front_index_ = -1;
  condition_ = -1;
  electrodes_ = 1;
  electrode_ = 0;
  tool_.fill(0);
  wear_.fill(0);
  constexpr double kPi = 3.14159265358979323846;
  for (int k = 0; k < kSides; ++k) {
    const double a = 2 * kPi * k / kSides;
    direction_[static_cast<std::size_t>(2 * k)] = std::cos(a);
    direction_[static_cast<std::size_t>(2 * k + 1)] = std::sin(a);
  }
}

void SimEdmProcess::mount(std::int32_t tool) noexcept {
  for (int e = 0; e < electrodes_; ++e)
    if (tool_[static_cast<std::size_t>(e)] == tool) {
      electrode_ = e;
      return;
    }
  electrode_ = electrodes_ < kMaxElectrodes ? electrodes_++ : kMaxElectrodes - 1;
  tool_[static_cast<std::size_t>(electrode_)] = tool;
  wear_[static_cast<std::size_t>(electrode_)] = 0;  // a new electrode (or one too many: the last slot anew)
}

void SimEdmProcess::replace(std::int32_t tool) noexcept {
  for (int e = 0; e < electrodes_; ++e)
    if (tool_[static_cast<std::size_t>(e)] == tool) wear_[static_cast<std::size_t>(e)] = 0;
}

double SimEdmProcess::electrode_wear_max_mm() const noexcept {
  double w = 0;
  for (int e = 0; e < electrodes_; ++e) w = std::max(w, wear_[static_cast<std::size_t>(e)]);
  return w;
}

// The condition's side gap and wear ratio, looked up when the generator's condition changes: the
// table's side gap, or the clean breakdown gap at its open voltage where the table gives none.
void SimEdmProcess::select(const GeneratorOutputs& gen) noexcept {
  if (gen.condition == condition_) return;
  condition_ = gen.condition;
  side_gap_mm_ = config_.breakdown_um_per_v * 1e-3 * gen.voltage_v;
  wear_ratio_ = 0;
  double reference_v = 0;
  for (int i = 0; i < config_.condition_count; ++i) {
    const SimEdmConditionEffect& c = config_.conditions[static_cast<std::size_t>(i)];
    if (c.number != gen.condition) continue;
    if (c.side_gap_mm > 0) side_gap_mm_ = c.side_gap_mm;
    wear_ratio_ = c.electrode_wear_ratio;
    reference_v = c.servo_reference_v;
  }
  // The share x of the breakdown distance at which the mean voltage (U0·t_d + Ue·t_on)/(t_d +
  // t_on + t_off) is the reference: t_d = (Ur·(t_on + t_off) − Ue·t_on)/(U0 − Ur), x = t_d/(t_on + t_d).
  double x_ref = 1;
  const double ton = std::max(gen.on_time_us, 0.1), toff = std::max(gen.off_time_us, 0.0);
  const double ue = config_.discharge_voltage_v;
  if (reference_v > 0 && reference_v < gen.voltage_v) {
    const double td = (reference_v * (ton + toff) - ue * ton) / (gen.voltage_v - reference_v);
    x_ref = std::clamp(td / (ton + std::max(td, 0.0)), 0.05, 1.0);
  }
  side_breakdown_mm_ = side_gap_mm_ / x_ref;
}

// The front of this orientation; a new one only where the generator sparks (create): B turning
// through 30° under G0 would otherwise take a front for every whole degree it passes and, beyond
// kMaxFronts, wipe the one burnt before. −1: none yet.
int SimEdmProcess::front_for(const double orientation[2], bool create) noexcept {
  std::int32_t k[2];
  for (int i = 0; i < 2; ++i) k[i] = static_cast<std::int32_t>(std::lround(orientation[i]));
  for (int f = 0; f < fronts_; ++f)
    if (key_[static_cast<std::size_t>(2 * f)] == k[0] && key_[static_cast<std::size_t>(2 * f + 1)] == k[1])
      return f;
  if (!create) return -1;
  const int f = fronts_ < kMaxFronts ? fronts_++ : kMaxFronts - 1;  // beyond eight: the last one again
  key_[static_cast<std::size_t>(2 * f)] = k[0];
  key_[static_cast<std::size_t>(2 * f + 1)] = k[1];
  front_[static_cast<std::size_t>(f)] = config_.surface_mm;
  burning_[static_cast<std::size_t>(f)] = false;
  for (int s = 0; s < kSides; ++s) wall_[static_cast<std::size_t>(f * kSides + s)] = 0;
  return f;
}

double SimEdmProcess::depth_mm() const noexcept {
  if (front_index_ < 0) return 0;
  return (front_[static_cast<std::size_t>(front_index_)] - config_.surface_mm) * config_.work_direction;
}

double SimEdmProcess::depth_max_mm() const noexcept {
  double d = 0;
  for (int f = 0; f < fronts_; ++f)
    d = std::max(d, (front_[static_cast<std::size_t>(f)] - config_.surface_mm) * config_.work_direction);
  return d;
}

double SimEdmProcess::side_wall_mm(int k) const noexcept {
  if (front_index_ < 0 || k < 0 || k >= kSides) return 0;
  return wall_[static_cast<std::size_t>(front_index_ * kSides + k)];
}

double SimEdmProcess::oversize_of(int front) const noexcept {
  double sum = 0;
  for (int k = 0; k < kSides; ++k) sum += wall_[static_cast<std::size_t>(front * kSides + k)];
  return sum / kSides;
}

double SimEdmProcess::cavity_oversize_mm() const noexcept {
  return front_index_ < 0 ? 0 : oversize_of(front_index_);
}

double SimEdmProcess::cavity_oversize_max_mm() const noexcept {
  double o = 0;
  for (int f = 0; f < fronts_; ++f) o = std::max(o, oversize_of(f));
  return o;
}

// The envelope of the side discharges: inside the cavity (the tip past the work's surface) and
// sparking, the electrode's sides burn the wall in each direction out to the side gap beyond
// where the electrode's outline stands (its lateral offset from the burn's centre along that
// direction). The side gap, not a removal rate, sets the size: an orbit's turn takes seconds, a
// side wall within the gap burns in milliseconds.
void SimEdmProcess::burn_sides(const SimEdmPose& pose, double tip) noexcept {
  const auto f = static_cast<std::size_t>(front_index_);
  if ((tip - config_.surface_mm) * config_.work_direction <= 0) return;  // not yet in the work
  const double d[2] = {config_.lateral_joints[0] >= 0 ? pose.lateral[0] - centre_[2 * f] : 0.0,
                       config_.lateral_joints[1] >= 0 ? pose.lateral[1] - centre_[2 * f + 1] : 0.0};
  for (int k = 0; k < kSides; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    const double reach = d[0] * direction_[2 * uk] + d[1] * direction_[2 * uk + 1] + side_gap_mm_;
    double& wall = wall_[f * kSides + uk];
    wall = std::max(wall, reach);
  }
}

void SimEdmProcess::step(const SimEdmPose& pose, bool generator_on, const GeneratorOutputs& gen,
                         SplitMix64& rng) noexcept {
  const double u0 = gen.voltage_v;
  front_index_ = front_for(pose.orientation, generator_on && u0 > 0);
  // The worn electrode's tip stands its lost length back from where the feed joint puts it.
  const double tip = pose.feed - config_.work_direction * electrode_wear_mm();
  constexpr double kNoWork = 1e9;  // no front at this orientation yet: nothing near the electrode
  gap_mm_ = front_index_ < 0
                ? kNoWork
                : (tip - front_[static_cast<std::size_t>(front_index_)]) * -config_.work_direction;
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
  select(gen);
  const auto f = static_cast<std::size_t>(front_index_);
  const bool removal = config_.side_walls == SideWalls::Removal;
  if (removal && burning_[f]) lateral_offset(pose, side_reach_);
  double x_side = 2;
  const int side = removal && burning_[f] ? narrowest_side(tip, x_side) : -1;
  const double x_front = gap_mm_ / breakdown;
  if (removal && !short_ && gap_mm_ > 0) debris_bridge(breakdown, rng);
  if (short_ || gap_mm_ <= 0 || (side >= 0 && x_side <= 0)) {
    state_ = GapState::Short;
    voltage_v_ = 0.5 + 0.2 * std::fabs(gauss(rng));
  } else if (removal ? std::min(x_front, x_side) >= 1 : gap_mm_ >= breakdown) {
    state_ = GapState::Open;
    voltage_v_ = u0 + config_.noise_v * gauss(rng);
  } else if (side >= 0 && x_side < x_front) {
    discharge(gen, x_side, side, rng);
  } else {
    if (removal && burning_[f]) edge_walls(gap_mm_);
    discharge(gen, x_front, -1, rng);
  }
  if (!burning_[f] && (state_ == GapState::Normal || state_ == GapState::Arc)) {  // the burn's centre
    burning_[f] = true;
    centre_[2 * f] = pose.lateral[0];
    centre_[2 * f + 1] = pose.lateral[1];
    if (removal) {  // the mouth of the cavity: the frontal gap round the outline
      lateral_offset(pose, side_reach_);
      edge_walls(gap_mm_);
    }
  }
  if (!removal && burning_[f] && state_ != GapState::Short) burn_sides(pose, tip);
}

// The electrode's lateral offset from the burn's centre (the joints it has).
void SimEdmProcess::lateral_offset(const SimEdmPose& pose, double d[2]) const noexcept {
  const auto f = static_cast<std::size_t>(front_index_);
  d[0] = config_.lateral_joints[0] >= 0 ? pose.lateral[0] - centre_[2 * f] : 0.0;
  d[1] = config_.lateral_joints[1] >= 0 ? pose.lateral[1] - centre_[2 * f + 1] : 0.0;
}

// The wall nearest to sparking: its distance from the electrode's outline (the wall less the
// outline's reach along its direction) over the side's breakdown distance, debris widening it as
// it widens the front's. None while the tip is not yet in the work.
int SimEdmProcess::narrowest_side(double tip, double& x) const noexcept {
  x = 2;
  const auto f = static_cast<std::size_t>(front_index_);
  if ((tip - config_.surface_mm) * config_.work_direction <= 0 || side_breakdown_mm_ <= 0) return -1;
  const double b = side_breakdown_mm_ * (1 + debris_);
  int best = -1;
  for (int k = 0; k < kSides; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    const double reach = side_reach_[0] * direction_[2 * uk] + side_reach_[1] * direction_[2 * uk + 1];
    const double xk = (wall_[f * kSides + uk] - reach) / b;
    if (xk < x) {
      x = xk;
      best = k;
    }
  }
  return best;
}

// The front's discharges at the electrode's edge leave the cavity's mouth the frontal gap wider
// than the outline in every direction the electrode faces (where the sides have not burnt further).
void SimEdmProcess::edge_walls(double gap) noexcept {
  const auto f = static_cast<std::size_t>(front_index_);
  for (int k = 0; k < kSides; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    const double reach = side_reach_[0] * direction_[2 * uk] + side_reach_[1] * direction_[2 * uk + 1];
    double& wall = wall_[f * kSides + uk];
    wall = std::max(wall, reach + gap);
  }
}

// Debris above short_debris bridges the gap now and then (more often the more there is): a short
// until the electrode has backed off half a breakdown gap further, as an injected bridge does.
void SimEdmProcess::debris_bridge(double breakdown, SplitMix64& rng) noexcept {
  if (config_.short_debris <= 0 || debris_ <= config_.short_debris) return;
  constexpr double kBridgesPerPeriod = 0.01;  // at twice the threshold, one period in a hundred
  const double p = kBridgesPerPeriod * std::min(1.0, (debris_ - config_.short_debris) / config_.short_debris);
  if (0.5 * (rng.symmetric() + 1) >= p) return;
  short_ = true;
  bridge_until_mm_ = gap_mm_ + 0.5 * breakdown;
}

// The discharges of one period: each waits an ignition delay that grows without bound as the gap
// nears the breakdown width (t_d = t_on·x/(1−x), x = gap / breakdown gap), burns for t_on at the
// discharge voltage and pauses t_off; the mean voltage is (U0·t_d + Ue·t_on)/(t_d + t_on + t_off).
// Debris above the threshold turns discharges into arcs (no delay, little removal) with a
// probability that grows with it. They burn the front (side < 0) or wall `side`: its area is its
// share of the electrode's outline times the cavity's depth.
void SimEdmProcess::discharge(const GeneratorOutputs& gen, double x, int side, SplitMix64& rng) noexcept {
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
  debris_ = std::min(2.0, debris_ + volume * config_.debris_per_mm3);
  discharges_ += static_cast<std::uint64_t>(n);
  if (side >= 0) {
    const auto f = static_cast<std::size_t>(front_index_);
    const double area = config_.electrode_perimeter_mm / kSides * std::max(depth_mm(), 0.001);
    const double b = side_breakdown_mm_ * (1 + debris_);
    const double room = b * (1 - x);  // a wall burns no further than where it stops sparking
    wall_[f * kSides + static_cast<std::size_t>(side)] += std::min(volume / area, room);
    return;
  }
  const double dz = std::min(volume / config_.electrode_area_mm2, gap_mm_);
  front_[static_cast<std::size_t>(front_index_)] += config_.work_direction * dz;
  // The electrode's face wears by the ratio of the volume (the same area): the gap closes less.
  const double worn = wear_ratio_ * dz;
  wear_[static_cast<std::size_t>(electrode_)] += worn;
  gap_mm_ -= dz - worn;
}

void SimEdmProcess::sample(ProcessInputs& in) const noexcept {
  in.gap_voltage_v = std::max(0.0, voltage_v_);
  in.gap_state = state_;
}

}  // namespace opencnc::machine
