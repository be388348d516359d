// SPDX-License-Identifier: GPL-3.0-or-later
// Simulated joint: cascaded drive loops, rigid mass with Coulomb/static/viscous friction,
// backlash as a play operator, pitch error table, quantised encoder, index marks, switches.
#include "opencnc/machine/sim_joint.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace opencnc::machine {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Axis units per SI unit: mm per m for linear joints, degrees per radian for rotary ones.
/// Accelerations come out of F/m in SI and are wanted in axis units.
double units_per_si(bool rotary) {
  return rotary ? 180.0 / std::numbers::pi : 1000.0;
}

}  // namespace

PitchErrorTable::PitchErrorTable(std::vector<PitchPoint> points) : points_(std::move(points)) {
  for (std::size_t i = 0; i + 1 < points_.size(); ++i) {
    slopes_.push_back((points_[i + 1].error - points_[i].error) /
                      (points_[i + 1].position - points_[i].position));
  }
}

double PitchErrorTable::at(double s) const noexcept {
  const std::size_t n = points_.size();
  if (n == 0) return 0.0;
  if (s <= points_.front().position) return points_.front().error;
  if (s >= points_.back().position) return points_.back().error;
  // Here n ≥ 2 and front < s < back; walk from the last segment (bounded by n).
  while (segment_ > 0 && s < points_[segment_].position) --segment_;
  while (segment_ + 2 < n && s >= points_[segment_ + 1].position) ++segment_;
  const PitchPoint& a = points_[segment_];
  return a.error + slopes_[segment_] * (s - a.position);
}

SimJoint::SimJoint(const SimJointConfig& config, double servo_period_s, int substeps, bool linear_periods)
    : config_(config),
      pitch_(config.model.pitch_error),
      limit_neg_(config.switches.limit_neg, config.switches.hysteresis, config.switches.noise),
      limit_pos_(config.switches.limit_pos, config.switches.hysteresis, config.switches.noise),
      home_(config.switches.home, config.switches.hysteresis, config.switches.noise),
      decel_(config.switches.decel, config.switches.hysteresis, config.switches.noise),
      h_(servo_period_s / substeps),
      unit_per_count_(1.0 / config.counts_per_unit),
      substeps_(substeps),
      period_s_(servo_period_s) {
  const SimJointModel& m = config.model;
  const double scale = units_per_si(config.rotary);
  accel_per_effort_ = scale / m.inertia;
  // The velocity loop sees the plant v = scale·F/(inertia·s); a gain of ω·inertia/scale puts
  // its crossover at ω, whatever the mass.
  velocity_gain_ = kTwoPi * m.velocity_bandwidth_hz * m.inertia / scale;
  velocity_integral_ = kTwoPi * m.velocity_integral_hz;
  // Exact discretisation of dF/dt = ωc (F_cmd − F) with F_cmd held over one sub-step.
  current_alpha_ = m.current_bandwidth_hz > 0 ? 1.0 - std::exp(-kTwoPi * m.current_bandwidth_hz * h_) : 1.0;
  power_per_effort_velocity_ = 1.0 / scale;
  half_backlash_ = m.backlash / 2;
  linear_periods_ = linear_periods && config.drive == JointDrive::Servo;
  // With a linear scale the loop closes around backlash and pitch error, which are not linear.
  linear_moving_ =
      linear_periods_ && (m.feedback == FeedbackSource::Motor || (m.backlash == 0 && m.pitch_error.empty()));
  encoder_bias_ = 0.5 * unit_per_count_;
  if (linear_periods_) {
    moving_map_ = build_period_map(false);
    held_map_ = build_period_map(true);
  }

  if (config.drive == JointDrive::Stepper) {
    steps_emitted_ = std::llround(m.start_position * config.counts_per_unit);
    motor_ = static_cast<double>(steps_emitted_) / config.counts_per_unit;
    stepper_dynamic_ = m.pullout_effort > 0;
  } else {
    motor_ = m.start_position;
  }
  hand_target_ = motor_;
  if (config.switches.home_sensor.present)
    home_sensor_ = SimProximity(config.switches.home, config.switches.home_sensor);
  screw_ = motor_;
  steps_at_period_start_ = steps_emitted_;
  cmd_.position = motor_;
  cmd_.step_position = steps_emitted_;
  feedback_at_period_start_ = feedback_raw();
}

JointCapabilities SimJoint::capabilities() const noexcept {
  JointCapabilities c;
  c.drive = config_.drive;
  const SwitchLayout& s = config_.switches;
  c.switches = static_cast<std::uint8_t>(
      (s.limit_neg.present ? kSwitchLimitNeg : 0) | (s.limit_pos.present ? kSwitchLimitPos : 0) |
      (s.home.present ? kSwitchHome : 0) | (s.decel.present ? kSwitchDecel : 0));
  const bool servo = config_.drive == JointDrive::Servo;
  c.index = servo && config_.model.index_spacing > 0;
  c.effort = servo;
  c.home_level = s.home.present && s.home_sensor.present;
  c.stall_detect = config_.drive == JointDrive::Stepper && config_.stall_detector;
  return c;
}

void SimJoint::set_hand_target(double target, double speed) noexcept {
  hand_target_ = target;
  hand_speed_ = std::abs(speed);
}

double SimJoint::table_position() const noexcept {
  return screw_ + pitch_.at(screw_);
}

double SimJoint::feedback_raw() const noexcept {
  if (config_.drive == JointDrive::Stepper)
    return static_cast<double>(steps_emitted_) / config_.counts_per_unit;
  if (config_.drive == JointDrive::Manual) return table_position();  // a scale on the quill
  return config_.model.feedback == FeedbackSource::Table ? table_position() : motor_;
}

// An incremental encoder counts whole lines: floor(x · counts_per_unit). The truncating cast
// plus a correction is floor() without a libm call on baseline x86-64. Positions beyond
// ±2^62 counts (or NaN) are clamped rather than overflowing the cast.
std::int64_t SimJoint::counts(double position) const noexcept {
  constexpr double kLimit = 0x1.0p62;
  const double q = position * config_.counts_per_unit;
  if (!(q > -kLimit)) return -static_cast<std::int64_t>(kLimit);
  if (!(q < kLimit)) return static_cast<std::int64_t>(kLimit);
  auto c = static_cast<std::int64_t>(q);
  if (static_cast<double>(c) > q) --c;
  return c;
}

/// The encoder reading as reported: counts / counts_per_unit, correctly rounded.
double SimJoint::quantise(double position) const noexcept {
  return static_cast<double>(counts(position)) / config_.counts_per_unit;
}

/// The same reading for the drive's own loop, by a multiplication: it differs from quantise()
/// by at most an ulp and keeps the division off each sub-step's dependency chain.
double SimJoint::quantise_fast(double position) const noexcept {
  return static_cast<double>(counts(position)) * unit_per_count_;
}

void SimJoint::begin_period(const JointOutputs& cmd, bool powered, double external_effort) noexcept {
  cmd_ = cmd;
  powered_ = powered && cmd.enable && !injected_fault_;
  external_effort_ = external_effort;
  steps_at_period_start_ = steps_emitted_;
  feedback_at_period_start_ = feedback_raw();
  energy_j_ = 0;
  if (!powered_) {
    effort_ = 0;
    position_integral_ = 0;
    velocity_error_integral_ = 0;
    command_direction_ = 0;
    accel_ff_shift_ = 0;
  } else if (config_.drive == JointDrive::Servo) {
    compensate_friction();
    feed_forward_acceleration();
  }
  last_velocity_ff_ = cmd.velocity_ff;
  period_moving_ = false;
  period_done_ = integrate_period();
}

// A drive's friction compensation. Starting from rest, the velocity loop's integrator has to
// build up the Coulomb friction from what it holds (nothing after a power-up) before the axis
// follows, and axes whose friction is larger against their inertia lag longer: coupled axes
// drift apart. So when the drive starts to move from rest or reverses, the integrator is
// *set* to hold at least the friction in the new direction. Setting rather than adding makes
// it bumpless: a standing torque the loop holds that way already (left from a deceleration) is
// kept, never doubled, and nothing is added while the command keeps its direction. The
// compensation stays below static friction, so by itself it does not move the axis.
void SimJoint::compensate_friction() noexcept {
  // The direction the drive wants to move: that of its velocity reference at the period's start
  // (the command's velocity and the position loop's correction), once it is beyond what a few
  // counts of following error ask for. An axis that overshot its end point and stuck starts
  // back before the command rests, and the loop's dithering at standstill starts nothing.
  constexpr double kDeadBandCounts = 4;
  const SimJointModel& m = config_.model;
  const double per_integral = velocity_gain_ * velocity_integral_;  // force per unit of the integral
  if (m.friction_compensation <= 0 || per_integral <= 0) return;
  const double error = cmd_.position - quantise_fast(feedback_raw());
  const double reference = m.feed_forward * cmd_.velocity_ff + m.position_gain * error;
  const double dead_band = m.position_gain * kDeadBandCounts * unit_per_count_;
  const int direction = std::abs(reference) <= dead_band ? 0 : reference > 0 ? 1 : -1;
  const bool start = direction != 0 && direction != command_direction_;
  command_direction_ = direction;
  if (!start) return;
  const double comp = m.friction_compensation;
  const double held = direction * velocity_error_integral_ * per_integral;  // in the new direction
  // Standing within static friction the loop may hold friction only: the integrator is set to
  // the compensation. Beyond it the loop holds a load (a weight) as well, which must stay: then
  // it is moved by the compensation at most.
  const bool friction_only = std::abs(held) <= m.static_friction;
  const double change = friction_only ? comp - held : std::min(comp, comp - held);
  if (change > 0) velocity_error_integral_ += direction * change / per_integral;
}

// Acceleration feed-forward: the drive derives the commanded acceleration from the change of
// the velocity feed-forward over the period and adds inertia × acceleration to its force
// command, so that the loops need no following error to accelerate or brake the axis (without
// it the axis lags while accelerating and leads while braking, then overshoots its end point
// and settles back against static friction: differently on each axis). Added to the force
// command for one period, it is the same as a shift of the velocity integrator by
// F / (Kv·ωi) that end_period() takes back — which keeps the period maps as they are.
void SimJoint::feed_forward_acceleration() noexcept {
  accel_ff_shift_ = 0;
  const double per_integral = velocity_gain_ * velocity_integral_;
  if (config_.model.acceleration_feed_forward <= 0 || per_integral <= 0) return;
  const double accel = (cmd_.velocity_ff - last_velocity_ff_) / period_s_;
  accel_ff_shift_ = config_.model.acceleration_feed_forward * accel / accel_per_effort_ / per_integral;
  velocity_error_integral_ += accel_ff_shift_;
}

double SimJoint::energy_j() const noexcept {
  if (!period_moving_) return energy_j_;
  double e = 0;
  for (int k = 0; k < SimPeriodMap::kSize; ++k) {
    double row = 0;
    for (int l = 0; l < SimPeriodMap::kSize; ++l) row += moving_map_.energy[k][l] * z_[l];
    e += z_[k] * row;
  }
  return e;
}

// Whole periods whose sub-steps can be summed up exactly: a stepper's steps (monotone within
// the period, so the play operator can be applied once at the end), a joint that stands
// without power and without a load that breaks it loose, and a linear drive.
bool SimJoint::integrate_period() noexcept {
  if (config_.drive == JointDrive::Manual) {
    integrate_hand_period();
    return true;
  }
  if (config_.drive == JointDrive::Stepper && stepper_dynamic_) return integrate_stepper_period();
  if (config_.drive == JointDrive::Stepper) {
    if (powered_) {
      steps_emitted_ = cmd_.step_position;
      motor_ = static_cast<double>(steps_emitted_) / config_.counts_per_unit;
      take_up_backlash();
    }
    return true;
  }
  if (!powered_) return velocity_ == 0.0 && std::abs(external_effort_) <= config_.model.static_friction;
  if (!linear_periods_) return false;
  if (velocity_ == 0.0) return integrate_held_period();
  return linear_moving_ && integrate_moving_period();
}

void SimJoint::substep(int i) noexcept {
  if (period_done_) return;
  if (config_.drive == JointDrive::Stepper) {
    stepper_substep(i);
  } else {
    servo_substep(h_ * i);
  }
}

// Drive cascade (see docs/machine.md): the position reference is the command extrapolated
// with the feed-forward velocity; P(I) position loop → velocity reference (clamped) → PI
// velocity loop → force command (clamped to peak) → first-order current loop. The
// integrators stop while their loop's output saturates.
void SimJoint::servo_substep(double t_s) noexcept {
  if (powered_) {
    const SimJointModel& m = config_.model;
    const double error = cmd_.position + cmd_.velocity_ff * t_s - quantise_fast(feedback_raw());
    double v_ref = m.feed_forward * cmd_.velocity_ff + m.position_gain * error +
                   m.position_integral * position_integral_;
    if (m.velocity_limit > 0 && std::abs(v_ref) > m.velocity_limit) {
      v_ref = std::copysign(m.velocity_limit, v_ref);
    } else {
      position_integral_ += error * h_;
    }
    const double v_error = v_ref - velocity_;
    double f_cmd = velocity_gain_ * (v_error + velocity_integral_ * velocity_error_integral_);
    if (std::abs(f_cmd) > m.peak_effort) {
      f_cmd = std::copysign(m.peak_effort, f_cmd);
    } else {
      velocity_error_integral_ += v_error * h_;
    }
    effort_ += current_alpha_ * (f_cmd - effort_);
  }
  integrate_mechanics(effort_);
  take_up_backlash();
}

namespace {

using Row = SimPeriodMap::Row;

// Coordinates of the period map (SimPeriodMap::z).
enum MapCoord : int {
  kRelPosition,    // feedback position − command position
  kRelVelocity,    // velocity − feed-forward velocity
  kForce,          // drive force
  kPosIntegral,    // position loop integrator
  kVelIntegral,    // velocity loop integrator
  kFeedForward,    // feed-forward velocity
  kConstantForce,  // external effort − Coulomb friction in the direction of motion
  kEncoderBias,    // feedback position − encoder reading
};

/// Per coefficient, the largest deviation of rows[i] from the chord between the first and the
/// last row.
Row bend_of(const std::vector<Row>& rows) {
  Row bend{};
  const Row& first = rows.front();
  const Row& last = rows.back();
  const double steps = static_cast<double>(rows.size() - 1);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double f = steps > 0 ? static_cast<double>(i) / steps : 0.0;
    for (std::size_t k = 0; k < bend.size(); ++k) {
      const double chord = first[k] + f * (last[k] - first[k]);
      bend[k] = std::max(bend[k], std::abs(rows[i][k] - chord));
    }
  }
  return bend;
}

}  // namespace

// servo_substep() and integrate_mechanics() are linear in z while no clamp acts and either
// the velocity keeps its sign (friction is then a constant force) or the axis is held by
// static friction all period (it does not move; the encoder reading is then exact). While
// moving, the encoder reading is taken as the position less half a count: its mean, the
// quantisation error being uniform over a count at any speed. A period is then a linear map
// of z, the product of the sub-step maps: running the sub-step equations on each unit vector
// of z gives its columns, and the coefficients of the clamped quantities in every sub-step
// give the bounds that tell whether a period stays linear.
SimPeriodMap SimJoint::build_period_map(bool held) const {
  const SimJointModel& m = config_.model;
  constexpr int n = SimPeriodMap::kSize;
  std::array<Row, SimPeriodMap::kStates> s{};  // s[state][k]: coefficient of z_k
  for (int k = 0; k < SimPeriodMap::kStates; ++k) s[k][k] = 1.0;
  std::vector<Row> velocity(1), force_command, velocity_reference;
  velocity[0][kRelVelocity] = velocity[0][kFeedForward] = 1.0;
  SimPeriodMap p;
  for (int i = 0; i < substeps_; ++i) {
    const double t = h_ * i;
    Row v_after{}, f_cmd_row{}, v_ref_row{}, force{};
    for (int k = 0; k < n; ++k) {
      const double vff = k == kFeedForward ? 1.0 : 0.0;
      const double load = k == kConstantForce ? 1.0 : 0.0;
      const double bias = k == kEncoderBias ? 1.0 : 0.0;
      double& d = s[kRelPosition][k];
      double& w = s[kRelVelocity][k];
      double& f = s[kForce][k];
      double& ip = s[kPosIntegral][k];
      double& iv = s[kVelIntegral][k];
      const double v = w + vff;
      const double error = vff * t - d + bias;
      const double v_ref = m.feed_forward * vff + m.position_gain * error + m.position_integral * ip;
      ip += error * h_;
      const double v_error = v_ref - v;
      const double f_cmd = velocity_gain_ * (v_error + velocity_integral_ * iv);
      iv += v_error * h_;
      f += current_alpha_ * (f_cmd - f);
      const double v_next = held ? 0.0 : v + accel_per_effort_ * (f + load - m.viscous_friction * v) * h_;
      d += v_next * h_;
      w = v_next - vff;
      v_after[k] = v_next;
      f_cmd_row[k] = f_cmd;
      v_ref_row[k] = v_ref;
      force[k] = f;
    }
    velocity.push_back(v_after);
    force_command.push_back(f_cmd_row);
    velocity_reference.push_back(v_ref_row);
    // energy_j += F·v·h per sub-step, both linear in z.
    for (int k = 0; k < n; ++k) {
      for (int l = 0; l < n; ++l) p.energy[k][l] += force[k] * v_after[l] * h_ * power_per_effort_velocity_;
    }
  }
  const Row bends[] = {bend_of(force_command), bend_of(velocity_reference), bend_of(velocity)};
  for (std::size_t k = 0; k < n; ++k) {
    auto& out = p.outputs[k];
    out[SimPeriodMap::kNextForce] = s[kForce][k];
    out[SimPeriodMap::kNextPosIntegral] = s[kPosIntegral][k];
    out[SimPeriodMap::kNextVelIntegral] = s[kVelIntegral][k];
    out[SimPeriodMap::kForceCommandFirst] = force_command.front()[k];
    out[SimPeriodMap::kForceCommandLast] = force_command.back()[k];
    out[SimPeriodMap::kVelRefFirst] = velocity_reference.front()[k];
    out[SimPeriodMap::kVelRefLast] = velocity_reference.back()[k];
    out[SimPeriodMap::kNextRelPosition] = s[kRelPosition][k];
    out[SimPeriodMap::kNextRelVelocity] = s[kRelVelocity][k];
    for (std::size_t b = 0; b < SimPeriodMap::kBends; ++b) p.bends[k][b] = bends[b][k];
  }
  return p;
}

/// A period map applied to z_: its outputs and bends (those not evaluated are zero).
struct SimJoint::MapValues {
  std::array<double, SimPeriodMap::kOutputs + 1> y{};
  std::array<double, SimPeriodMap::kBends + 1> bend{};
  double operator[](int output) const noexcept { return y[static_cast<std::size_t>(output)]; }
  double largest(int first, int bend_index) const noexcept {
    const auto f = static_cast<std::size_t>(first);
    return std::max(std::abs(y[f]), std::abs(y[f + 1])) + bend[static_cast<std::size_t>(bend_index)];
  }
};

// The first Rows outputs and Bends bends, column by column into local sums, so that the compiler
// keeps them in registers and runs the rows side by side (two to an SSE2 register).
template <std::size_t Rows, std::size_t Bends>
SimJoint::MapValues SimJoint::evaluate(const SimPeriodMap& map) const noexcept {
  std::array<double, Rows> y{};
  std::array<double, Bends> bend{};
  for (std::size_t k = 0; k < SimPeriodMap::kSize; ++k) {
    const double zk = z_[k], ak = std::abs(z_[k]);
#pragma GCC unroll 16
    for (std::size_t r = 0; r < Rows; ++r) y[r] += map.outputs[k][r] * zk;
#pragma GCC unroll 16
    for (std::size_t r = 0; r < Bends; ++r) bend[r] += map.bends[k][r] * ak;
  }
  MapValues v;
  std::copy(y.begin(), y.end(), v.y.begin());
  std::copy(bend.begin(), bend.end(), v.bend.begin());
  return v;
}

// No sub-step of the period clamps the force command or the velocity reference.
bool SimJoint::within_limits(const MapValues& y) const noexcept {
  const SimJointModel& m = config_.model;
  return y.largest(SimPeriodMap::kForceCommandFirst, SimPeriodMap::kForceCommandBend) <= m.peak_effort &&
         (m.velocity_limit <= 0 ||
          y.largest(SimPeriodMap::kVelRefFirst, SimPeriodMap::kVelRefBend) <= m.velocity_limit);
}

void SimJoint::take_state(const MapValues& y) noexcept {
  effort_ = y[SimPeriodMap::kNextForce];
  position_integral_ = y[SimPeriodMap::kNextPosIntegral];
  velocity_error_integral_ = y[SimPeriodMap::kNextVelIntegral];
}

void SimJoint::load_state(double feedback) noexcept {
  z_[kRelPosition] = feedback - cmd_.position;
  z_[kRelVelocity] = velocity_ - cmd_.velocity_ff;
  z_[kForce] = effort_;
  z_[kPosIntegral] = position_integral_;
  z_[kVelIntegral] = velocity_error_integral_;
  z_[kFeedForward] = cmd_.velocity_ff;
}

// Moving one way all period: the velocity at the start and at the end have the same sign and
// the chord between them stays further from zero (by a count per period) than the velocity can
// bend away from it. The motor moves one way, so the backlash is taken up once at the end.
bool SimJoint::integrate_moving_period() noexcept {
  load_state(feedback_raw());
  z_[kConstantForce] = external_effort_ - std::copysign(config_.model.coulomb_friction, velocity_);
  z_[kEncoderBias] = encoder_bias_;
  const MapValues y = evaluate<SimPeriodMap::kOutputs + 1, SimPeriodMap::kBends + 1>(moving_map_);
  const double v_end = cmd_.velocity_ff + y[SimPeriodMap::kNextRelVelocity];
  // The mean encoder error stands for the real one only while the motion crosses counts.
  const double v_min = std::min(std::abs(velocity_), std::abs(v_end)) - unit_per_count_ / period_s_;
  if (!((v_end > 0) == (velocity_ > 0) && v_min > y.bend[SimPeriodMap::kVelocityBend]) || !within_limits(y))
    return false;
  motor_ = cmd_.position + y[SimPeriodMap::kNextRelPosition];
  velocity_ = v_end;
  take_state(y);
  take_up_backlash();
  period_moving_ = true;
  return true;
}

// Held by static friction all period: the feedback does not change and its reading is exact.
// The force is a first-order lag of the force command (each sub-step a convex combination of
// the two), so it stays within static friction when it starts there and the command does.
bool SimJoint::integrate_held_period() noexcept {
  const SimJointModel& m = config_.model;
  const double feedback = feedback_raw();
  load_state(feedback);
  z_[kConstantForce] = 0;
  z_[kEncoderBias] = feedback - quantise_fast(feedback);
  const MapValues y = m.velocity_limit > 0 ? evaluate<SimPeriodMap::kVelRefLast + 1, 2>(held_map_)
                                           : evaluate<SimPeriodMap::kForceCommandLast + 1, 1>(held_map_);
  const double load = external_effort_;
  const double command = std::max(std::abs(y.y[SimPeriodMap::kForceCommandFirst] + load),
                                  std::abs(y.y[SimPeriodMap::kForceCommandLast] + load)) +
                         y.bend[SimPeriodMap::kForceCommandBend];
  if (!(std::abs(effort_ + load) <= m.static_friction && command <= m.static_friction && within_limits(y)))
    return false;
  take_state(y);
  return true;
}

// Rigid body with friction, semi-implicit Euler. At rest the body sticks while the applied
// effort stays within static friction; moving, Coulomb and viscous friction oppose the
// velocity, and a sign change inside a sub-step ends at rest (the next sub-step decides
// whether it sticks) so that friction never drives the body.
void SimJoint::integrate_mechanics(double drive_effort) noexcept {
  const SimJointModel& m = config_.model;
  const double applied = drive_effort + external_effort_;
  double v = velocity_;
  if (v == 0.0) {
    if (std::abs(applied) <= m.static_friction) return;
    v = accel_per_effort_ * (applied - std::copysign(m.coulomb_friction, applied)) * h_;
  } else {
    const double net = applied - m.viscous_friction * v - std::copysign(m.coulomb_friction, v);
    const double v_next = v + accel_per_effort_ * net * h_;
    v = (v_next > 0) == (v > 0) ? v_next : 0.0;
  }
  velocity_ = v;
  motor_ += v * h_;
  energy_j_ += drive_effort * v * h_ * power_per_effort_velocity_;
}

// Backlash as a play operator: the nut (screw_) follows the motor only once the motor has
// taken up half the lost motion on either side.
void SimJoint::take_up_backlash() noexcept {
  const double slack = motor_ - screw_;
  if (slack > half_backlash_) {
    screw_ = motor_ - half_backlash_;
  } else if (slack < -half_backlash_) {
    screw_ = motor_ + half_backlash_;
  }
}

// A stepper with a pull-out curve, one period: the steps are emitted whatever the rotor does.
// In step, the rotor follows them if the effort the period asks — mass × the change of step rate,
// friction against the motion, minus the load (at rest: the load beyond static friction) — is
// within the pull-out effort at that speed; otherwise it drops out of step. The step rate is
// taken through a first-order lag of kRotorLag_s: the rotor's load angle absorbs the jitter of
// whole steps from period to period (one step more or less is far inside the ±1 full step it may
// lag), so only sustained accelerations count. Out of step (or without power) it coasts under
// friction and load, and it locks on the nearest step again once the steps and the rotor are
// both at rest; the steps emitted meanwhile are lost.
bool SimJoint::integrate_stepper_period() noexcept {
  constexpr double kRotorLag_s = 0.004;
  const SimJointModel& m = config_.model;
  const double spu = config_.counts_per_unit;
  const double v_steps =
      powered_ ? static_cast<double>(cmd_.step_position - steps_emitted_) / spu / period_s_ : 0.0;
  if (powered_) steps_emitted_ = cmd_.step_position;
  if (powered_ && !stalled_ && in_step_) {
    const double smoothed =
        step_velocity_ + (v_steps - step_velocity_) * period_s_ / (period_s_ + kRotorLag_s);
    const double accel = (smoothed - step_velocity_) / period_s_;
    const double need = v_steps != 0.0
                            ? accel / accel_per_effort_ + std::copysign(m.coulomb_friction, v_steps) +
                                  m.viscous_friction * v_steps - external_effort_
                            : std::max(0.0, std::abs(external_effort_) - m.static_friction) +
                                  std::abs(accel / accel_per_effort_);
    const double reach = m.pullout_speed > 0 ? std::max(0.0, 1.0 - std::abs(v_steps) / m.pullout_speed) : 1.0;
    step_velocity_ = smoothed;
    if (std::abs(need) <= m.pullout_effort * reach) {
      motor_ = static_cast<double>(steps_emitted_ - lost_steps_) / spu;
      velocity_ = v_steps;
      take_up_backlash();
      return true;
    }
    stalled_ = true;  // out of step, with the speed the rotor had
  }
  in_step_ = false;
  step_velocity_ = v_steps;
  coast();
  if (powered_ && v_steps == 0.0 && velocity_ == 0.0) {
    const std::int64_t at = std::llround(motor_ * spu);
    lost_steps_ = steps_emitted_ - at;
    motor_ = static_cast<double>(at) / spu;
    stalled_ = false;
    in_step_ = true;
    take_up_backlash();
  }
  return true;
}

/// A period of free motion (no drive effort) under friction and the load, sub-step by sub-step.
void SimJoint::coast() noexcept {
  for (int i = 0; i < substeps_; ++i) {
    integrate_mechanics(0.0);
    take_up_backlash();
  }
}

// The operator's hand: toward the target at up to the hand speed, with a hand's acceleration,
// braking so as to stop on the target (a quill against its depth stop).
void SimJoint::integrate_hand_period() noexcept {
  const double a_max = kHandAcceleration;
  for (int i = 0; i < substeps_; ++i) {
    const double d = hand_target_ - motor_;
    if (d == 0.0 && velocity_ == 0.0) break;
    const double want = std::copysign(std::min(hand_speed_, std::sqrt(2.0 * a_max * std::abs(d))), d);
    velocity_ += std::clamp(want - velocity_, -a_max * h_, a_max * h_);
    const double step = velocity_ * h_;
    if ((d > 0 && step >= d) || (d < 0 && step <= d) || d == 0.0) {
      motor_ = hand_target_;
      velocity_ = 0;
    } else {
      motor_ += step;
    }
  }
  screw_ = motor_;
}

// The step generator spreads this period's steps evenly; sub-step i has emitted the share
// up to its end. An unpowered stepper emits nothing (and so loses its place).
void SimJoint::stepper_substep(int i) noexcept {
  if (!powered_) return;
  const std::int64_t delta = cmd_.step_position - steps_at_period_start_;
  steps_emitted_ = steps_at_period_start_ + delta * (i + 1) / substeps_;
  motor_ = static_cast<double>(steps_emitted_) / config_.counts_per_unit;
  take_up_backlash();
}

void SimJoint::end_period() noexcept {
  velocity_error_integral_ -= accel_ff_shift_;
  accel_ff_shift_ = 0;
  if (config_.drive == JointDrive::Stepper && !stepper_dynamic_) {
    velocity_ =
        static_cast<double>(steps_emitted_ - steps_at_period_start_) / config_.counts_per_unit / period_s_;
  }
  if (config_.drive == JointDrive::Servo && config_.model.index_spacing > 0) {
    update_index(feedback_at_period_start_, feedback_raw());
  }
}

// Index marks sit at index_offset + k·index_spacing on the feedback scale. A period moves far
// less than one spacing, so comparing the mark numbers at its ends finds the marks passed.
void SimJoint::update_index(double before, double after) noexcept {
  const double spacing = config_.model.index_spacing;
  const double offset = config_.model.index_offset;
  const double k_before = std::floor((before - offset) / spacing);
  const double k_after = std::floor((after - offset) / spacing);
  if (k_before == k_after) return;
  index_count_ += static_cast<std::uint32_t>(std::abs(k_after - k_before));
  const double last_mark = k_after > k_before ? k_after : k_after + 1;
  index_position_ = quantise(offset + last_mark * spacing);
}

void SimJoint::sample(JointInputs& in, SplitMix64& rng, double temperature_c) noexcept {
  const bool servo = config_.drive == JointDrive::Servo;
  in.position = config_.drive == JointDrive::Stepper ? feedback_raw() : quantise(feedback_raw());
  in.velocity = velocity_;
  in.effort = servo ? effort_ : 0.0;
  in.index_count = index_count_;
  in.index_position = index_position_;
  in.amp_fault = injected_fault_;
  in.stall = config_.stall_detector && stalled_;
  const double x = table_position();
  in.limit_neg = limit_neg_.update(x, rng);
  in.limit_pos = limit_pos_.update(x, rng);
  if (home_sensor_.present()) {
    in.home = home_sensor_.update(x, temperature_c, rng);
    in.home_level = home_sensor_.level();
  } else {
    in.home = home_.update(x, rng);
  }
  in.decel = decel_.update(x, rng);
}

}  // namespace opencnc::machine
