// SPDX-License-Identifier: GPL-3.0-or-later
// AxisMover: acceleration-limited generator with exact stops, plus the jerk-limiting average.
#include "opencnc/control/axis_mover.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::control {

void AxisMover::configure(double period_s, double max_acceleration, double max_jerk,
                          double position) noexcept {
  period_ = period_s;
  accel_ = max_acceleration;
  int m = 1;
  if (max_jerk > 0) m = static_cast<int>(std::ceil(2.0 * max_acceleration / (max_jerk * period_s) - 1e-9));
  filter_ticks_ = std::clamp(m, 1, traj::kMaxFilterTicks);
  reset(position);
}

void AxisMover::reset(double position) noexcept {
  goal_ = Goal::Velocity;
  goal_velocity_ = 0;
  goal_position_ = position;
  raw_ = out_ = position;
  vel_ = 0;
  for (int i = 0; i < filter_ticks_; ++i) history_[static_cast<std::size_t>(i)] = position;
  head_ = 0;
  sum_ = position * filter_ticks_;
  still_ = filter_ticks_;
}

void AxisMover::move_to(double target, double speed) noexcept {
  goal_ = Goal::Position;
  goal_position_ = target;
  goal_speed_ = std::fabs(speed);
}

void AxisMover::run_at(double velocity) noexcept {
  goal_ = Goal::Velocity;
  goal_velocity_ = velocity;
}

double AxisMover::stopping_distance() const noexcept {
  return vel_ * vel_ / (2.0 * accel_);
}

void AxisMover::step_velocity() noexcept {
  const double dv = std::clamp(goal_velocity_ - vel_, -accel_ * period_, accel_ * period_);
  const double v1 = vel_ + dv;
  raw_ += 0.5 * (vel_ + v1) * period_;
  vel_ = v1;
}

// In the frame where the goal lies ahead (distance D ≥ 0, speed u toward it), the largest end
// speed u' of a period with constant acceleration that keeps u'² ≤ 2A·(D − (u + u')T/2) is
// u' = (√((AT)² + 8AD − 4ATu) − AT)/2. Following it, v² = 2A·d holds exactly at every period
// end, so the speed falls by A·T per period; once it is below A·T/2 the rest of the way fits
// in one period at less than A, and the generator lands on the goal at rest.
void AxisMover::step_position() noexcept {
  const double d = goal_position_ - raw_;
  // On the goal with a speed a period's braking takes away (the rounding of the last steps can
  // leave one of a few 1e-10 whose sign the frame below flips every period): at rest.
  if (d == 0 && std::fabs(vel_) <= accel_ * period_) {
    vel_ = 0;
    return;
  }
  const double dir = d > 0 ? 1.0 : (d < 0 ? -1.0 : (vel_ > 0 ? -1.0 : 1.0));
  const double D = std::fabs(d), u = dir * vel_, at = accel_ * period_;
  if (u >= 0 && u <= at && D <= 0.5 * u * period_ + 1e-12) {
    raw_ = goal_position_;
    vel_ = 0;
    return;
  }
  const double disc = at * at + 8.0 * accel_ * D - 4.0 * at * u;
  const double brake = disc > 0 ? 0.5 * (std::sqrt(disc) - at) : 0.0;
  double u1 = std::min({goal_speed_, u + at, brake});
  u1 = std::max(u1, u - at);
  raw_ += dir * 0.5 * (u + u1) * period_;
  vel_ = dir * u1;
  if (dir * (goal_position_ - raw_) < 0 && u1 <= at) {  // rounding: never beyond the goal
    raw_ = goal_position_;
    vel_ = 0;
  }
}

double AxisMover::filter() noexcept {
  const int m = filter_ticks_;
  if (m <= 1) return raw_;
  double& slot = history_[static_cast<std::size_t>(head_)];
  sum_ += raw_ - slot;
  slot = raw_;
  head_ = head_ + 1 == m ? 0 : head_ + 1;
  if (still_ >= m) {  // the window holds only the resting position: exact
    sum_ = raw_ * m;
    return raw_;
  }
  if (head_ == 0) {  // once per window, drop the rounding the running sum has gathered
    sum_ = 0;
    for (int i = 0; i < m; ++i) sum_ += history_[static_cast<std::size_t>(i)];
  }
  return sum_ / m;
}

double AxisMover::tick() noexcept {
  const double before = raw_;
  if (goal_ == Goal::Position) {
    step_position();
  } else {
    step_velocity();
  }
  still_ = raw_ == before && vel_ == 0 ? still_ + 1 : 0;
  out_ = filter();
  return out_;
}

}  // namespace opencnc::control
