// SPDX-License-Identifier: GPL-3.0-or-later
// Compensation: pitch-error lookup, the direction of motion, and the rate-limited take-up.
#include "opencnc/motion/compensation.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::motion {

double pitch_error(const PitchTable& t, double x, int direction, int& segment) noexcept {
  const int n = t.count;
  if (n <= 0) return 0.0;
  const auto value = [&](int i) {
    const auto k = static_cast<std::size_t>(i);
    if (direction > 0) return t.forward[k];
    if (direction < 0) return t.reverse[k];
    return 0.5 * (t.forward[k] + t.reverse[k]);
  };
  if (n == 1 || x <= t.position[0]) return value(0);
  if (x >= t.position[static_cast<std::size_t>(n - 1)]) return value(n - 1);
  // Here n ≥ 2 and position[0] < x < position[n−1]; walk from the hint (at most n steps).
  int i = std::clamp(segment, 0, n - 2);
  while (i > 0 && x < t.position[static_cast<std::size_t>(i)]) --i;
  while (i + 2 < n && x >= t.position[static_cast<std::size_t>(i + 1)]) ++i;
  segment = i;
  const double x0 = t.position[static_cast<std::size_t>(i)], x1 = t.position[static_cast<std::size_t>(i + 1)];
  const double f = (x - x0) / (x1 - x0);
  return value(i) + f * (value(i + 1) - value(i));
}

double Compensation::target(int j, double x) noexcept {
  JointState& s = state_[index(j)];
  const JointCompensation& c = config_.joints[index(j)];
  const double pitch = s.homed ? pitch_error(pitch_table(j), x, s.direction, s.segment) : 0.0;
  return -pitch + 0.5 * c.backlash * s.direction;
}

double Compensation::update(int j, double joint_position, double offset, bool homed) noexcept {
  if (j < 0 || j >= kMaxCompensatedJoints) return 0.0;
  JointState& s = state_[index(j)];
  const JointCompensation& c = config_.joints[index(j)];
  if (!c.enabled) return 0.0;
  if (!s.started) {
    s.started = true;
    s.last_position = joint_position;
  }
  // The direction of the commanded motion; at rest it keeps the last one (as the nut does).
  const double p = joint_position, x = joint_position + offset;
  const int direction = p > s.last_position ? 1 : (p < s.last_position ? -1 : s.direction);
  s.last_position = p;
  s.last_x = x;
  const bool jumped = direction != s.direction || homed != s.homed;
  const double before = s.target;
  s.direction = direction;
  s.homed = homed;
  s.target = target(j, x);
  if (jumped) s.take_up -= s.target - before;  // c stays where it was; u runs the jump off
  run_take_up(s, c);
  s.correction = s.target + s.take_up;
  return s.correction;
}

// The target's backlash term is direction · B/2: a new B moves the target by direction · ΔB/2,
// which u takes up from where c stands (c = target + u stays continuous).
void Compensation::set_backlash(int j, double backlash, double max_velocity,
                                double max_acceleration) noexcept {
  if (j < 0 || j >= kMaxCompensatedJoints) return;
  JointCompensation& c = config_.joints[index(j)];
  JointState& s = state_[index(j)];
  const double shift = s.direction * (backlash - c.backlash) / 2;
  c.backlash = backlash;
  c.max_velocity = max_velocity;
  c.max_acceleration = max_acceleration;
  s.target += shift;
  s.take_up -= shift;
}

// As set_backlash: the target at the joint's last position moves to the new table's value, and u
// takes the difference up from where c stands. Before the first update there is nothing to take up.
void Compensation::set_pitch_table(int j, const PitchTable* table) noexcept {
  if (j < 0 || j >= kMaxCompensatedJoints) return;
  tables_[index(j)] = table;
  JointState& s = state_[index(j)];
  s.segment = 0;
  if (!s.started) return;
  const double before = s.target;
  s.target = target(j, s.last_x);
  s.take_up -= s.target - before;
}

// u toward 0, time-optimal under |u̇| ≤ V and |ü| ≤ A with the position updated by the new
// velocity (u += v·T). From speed v, braking by A·T every period covers T·(v + (v − AT) + …),
// which stays within the distance D left iff v ≤ (√((AT)² + 8AD) − AT)/2: that speed toward 0,
// at most V, is what each period aims for, within A·T of the last speed. The period that can
// reach 0 exactly (with an acceptable change of speed) lands there.
void Compensation::run_take_up(JointState& s, const JointCompensation& c) const noexcept {
  const double u = s.take_up, v = s.take_up_velocity;
  if (u == 0.0 && v == 0.0) return;
  const double T = config_.period_s, A = c.max_acceleration, V = c.max_velocity;
  if (!(A > 0) || !(V > 0)) {  // no limits given: take it up at once
    s.take_up = s.take_up_velocity = 0;
    return;
  }
  const double d = -u, D = std::abs(d);
  const double dv = A * T;
  const double land = d / T;  // the speed that reaches 0 in this period
  if (std::abs(land - v) <= dv && std::abs(land) <= V) {
    // Reaching 0 now is allowed; the next period then stops from `land` (≤ A·T away, see below).
    if (std::abs(land) <= dv) {
      s.take_up = 0;
      s.take_up_velocity = land;
      return;
    }
  }
  const double brake = 0.5 * (std::sqrt(dv * dv + 8.0 * A * D) - dv);
  const double want = std::copysign(std::min(V, brake), d);
  const double next = std::clamp(want, v - dv, v + dv);
  s.take_up_velocity = next;
  s.take_up = u + next * T;
  if (D == 0.0 && next == 0.0) s.take_up = 0;
}

}  // namespace opencnc::motion
