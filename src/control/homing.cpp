// SPDX-License-Identifier: GPL-3.0-or-later
// JointHoming: one joint's homing phases, edge latching and the move to the home position.
#include "opencnc/control/homing.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::control {

namespace {

bool same_direction(double a, double b) noexcept {
  return (a > 0) == (b > 0);
}

}  // namespace

const char* to_string(HomingPhase p) noexcept {
  switch (p) {
    case HomingPhase::Idle:
      return "idle";
    case HomingPhase::Clear:
      return "clear";
    case HomingPhase::Search:
      return "search";
    case HomingPhase::BackOff:
      return "back-off";
    case HomingPhase::Latch:
      return "latch";
    case HomingPhase::Index:
      return "index";
    case HomingPhase::Overrun:
      return "overrun";
    case HomingPhase::Return:
      return "return";
    case HomingPhase::Measure:
      return "measure";
    case HomingPhase::Center:
      return "center";
    case HomingPhase::Final:
      return "final";
    case HomingPhase::Done:
      return "done";
    case HomingPhase::Failed:
      return "failed";
  }
  return "?";
}

void EdgeInterpolator::add(double position, double level) noexcept {
  if (count_ > 0 && position == position_) {
    sum_ += level;
    ++count_;
    return;
  }
  if (count_ > 0) {
    previous_position_ = position_;
    previous_level_ = sum_ / count_;
    have_previous_ = true;
  }
  position_ = position;
  sum_ = level;
  count_ = 1;
}

double EdgeInterpolator::crossing(double level) const noexcept {
  const double now = count_ > 0 ? sum_ / count_ : level;
  if (!have_previous_ || now == previous_level_) return position_;
  const double f = std::clamp((level - previous_level_) / (now - previous_level_), 0.0, 1.0);
  return previous_position_ + f * (position_ - previous_position_);
}

void JointHoming::start(const HomeConfig& c, const HomingInputs& in) noexcept {
  stopping_ = false;
  latch_on_release_ = false;
  index_count_ = in.index_count;
  previous_feedback_ = in.feedback;
  switch (c.method) {
    case HomeMethod::Immediate:
      phase_ = HomingPhase::Latch;
      break;
    case HomeMethod::Index:
      phase_ = HomingPhase::Index;
      break;
    case HomeMethod::Switch:
    case HomeMethod::SwitchIndex:
      phase_ = in.home_switch ? HomingPhase::Clear : HomingPhase::Search;
      break;
    case HomeMethod::DecelHome:
      phase_ =
          in.home_switch ? HomingPhase::Clear : (in.decel_switch ? HomingPhase::Latch : HomingPhase::Search);
      break;
    case HomeMethod::DecelMidpoint:
      phase_ = in.home_switch || in.decel_switch ? HomingPhase::Clear : HomingPhase::Search;
      edge_.reset();
      sensor_on_ = false;
      break;
  }
}

void JointHoming::cancel(AxisMover& mover) noexcept {
  if (active()) mover.stop();
  phase_ = HomingPhase::Idle;
  stopping_ = false;
}

bool JointHoming::trigger(const HomingInputs& in) const noexcept {
  return latch_on_release_ ? !in.home_switch : in.home_switch;
}

void JointHoming::latch(const HomeConfig& c, double joint_position, double& offset) noexcept {
  latched_at_ = joint_position;
  offset_ = c.switch_position - joint_position;
  offset = offset_;
}

void JointHoming::after_switch_latch(const HomeConfig& c, AxisMover& mover) noexcept {
  if (c.method == HomeMethod::SwitchIndex) {
    phase_ = HomingPhase::Index;  // keep moving at latch velocity to the next mark
    return;
  }
  mover.stop();
  stopping_ = true;
  phase_ = HomingPhase::Final;
}

void JointHoming::tick(const HomeConfig& c, const HomingInputs& in, AxisMover& mover,
                       double& offset) noexcept {
  step(c, in, mover, offset);
  previous_feedback_ = in.feedback;
}

void JointHoming::step(const HomeConfig& c, const HomingInputs& in, AxisMover& mover,
                       double& offset) noexcept {
  if (stopping_) {
    if (!mover.settled()) return;
    stopping_ = false;
  }
  if (c.method == HomeMethod::DecelMidpoint) {
    step_midpoint(c, in, mover, offset);
    return;
  }
  const bool decel_home = c.method == HomeMethod::DecelHome;
  switch (phase_) {
    case HomingPhase::Idle:
    case HomingPhase::Done:
    case HomingPhase::Failed:
    case HomingPhase::Overrun:
    case HomingPhase::Return:
    case HomingPhase::Measure:
    case HomingPhase::Center:
      break;
    case HomingPhase::Clear:
      mover.run_at(-c.search_velocity);
      if (!in.home_switch && !(decel_home && in.decel_switch)) {
        mover.stop();
        stopping_ = true;
        phase_ = HomingPhase::Search;
      }
      break;
    case HomingPhase::Search:
      mover.run_at(c.search_velocity);
      if (decel_home) {
        if (in.decel_switch) {  // on the dog: slow down to latch speed, no stop
          phase_ = HomingPhase::Latch;
          mover.run_at(c.latch_velocity);
        }
      } else if (in.home_switch) {
        mover.stop();
        stopping_ = true;
        if (same_direction(c.latch_velocity, c.search_velocity)) {
          phase_ = HomingPhase::BackOff;
        } else {
          phase_ = HomingPhase::Latch;
          latch_on_release_ = true;
        }
      }
      break;
    case HomingPhase::BackOff:
      mover.run_at(-c.latch_velocity);
      if (!in.home_switch) {
        mover.stop();
        stopping_ = true;
        phase_ = HomingPhase::Latch;
      }
      break;
    case HomingPhase::Latch:
      if (c.method == HomeMethod::Immediate) {  // no edge: the present position is `position`
        latched_at_ = in.feedback;
        offset_ = offset = c.position - in.feedback;
        phase_ = HomingPhase::Done;
        break;
      }
      mover.run_at(c.latch_velocity);
      if (trigger(in)) {
        // The edge came between the last sample and this one: take the middle, which halves
        // the error the sampling adds (latch velocity × period).
        if (c.method != HomeMethod::SwitchIndex) latch(c, 0.5 * (in.feedback + previous_feedback_), offset);
        index_count_ = in.index_count;
        after_switch_latch(c, mover);
      }
      break;
    case HomingPhase::Index:
      mover.run_at(c.latch_velocity);
      if (in.index_count != index_count_) {
        latch(c, in.index_position, offset);
        mover.stop();
        stopping_ = true;
        phase_ = HomingPhase::Final;
      }
      break;
    case HomingPhase::Final:
      mover.move_to(c.position - offset_, c.final_velocity);
      if (mover.settled()) phase_ = HomingPhase::Done;
      break;
  }
}

// The seed's precise origin. Past the dog and back in the working direction, the sensor is met
// with the backlash taken up; its rising edge (the level crossing level_on) and its falling edge
// (below level_off) are both interpolated between periods, and their middle is the origin: a
// shift of the sensing distance (temperature) moves the two edges apart, not their middle.
void JointHoming::step_midpoint(const HomeConfig& c, const HomingInputs& in, AxisMover& mover,
                                double& offset) noexcept {
  const double toward_dog = c.search_velocity > 0 ? 1.0 : -1.0;
  switch (phase_) {
    case HomingPhase::Clear:  // on the dog or the sensor already: off them, against the search
      mover.run_at(-c.search_velocity);
      if (!in.home_switch && !in.decel_switch) {
        mover.stop();
        stopping_ = true;
        phase_ = HomingPhase::Search;
      }
      break;
    case HomingPhase::Search:
      mover.run_at(c.search_velocity);
      if (in.decel_switch) {
        dog_at_ = in.feedback;
        mover.move_to(dog_at_ + toward_dog * c.overrun, std::abs(c.search_velocity));
        phase_ = HomingPhase::Overrun;
      }
      break;
    case HomingPhase::Overrun:
      if (!mover.settled()) break;
      edge_.reset();
      sensor_on_ = in.home_level >= c.level_on;
      if (sensor_on_ || !in.decel_switch) {  // the overrun did not take it past the sensor, or off the dog
        phase_ = HomingPhase::Failed;
        break;
      }
      mover.run_at(c.return_velocity);
      phase_ = HomingPhase::Return;
      break;
    case HomingPhase::Return:
    case HomingPhase::Measure:
      edge_.add(in.feedback, in.home_level);
      if (!in.decel_switch) {  // left the dog without both edges: the sensor is not on it
        mover.stop();
        phase_ = HomingPhase::Failed;
      } else if (phase_ == HomingPhase::Return && in.home_level >= c.level_on) {
        rising_ = edge_.crossing(c.level_on);
        sensor_on_ = true;
        mover.run_at(c.latch_velocity);
        phase_ = HomingPhase::Measure;
      } else if (phase_ == HomingPhase::Measure && in.home_level < c.level_off) {
        falling_ = edge_.crossing(c.level_off);
        sensor_on_ = false;
        latch(c, 0.5 * (rising_ + falling_), offset);
        mover.stop();
        stopping_ = true;
        phase_ = HomingPhase::Center;
      }
      break;
    case HomingPhase::Center:  // back S/2: the middle of the on-zone
      mover.move_to(latched_at_, std::abs(c.return_velocity));
      if (mover.settled()) phase_ = HomingPhase::Final;
      break;
    case HomingPhase::Final:
      mover.move_to(c.position - offset_, c.final_velocity);
      if (mover.settled()) phase_ = HomingPhase::Done;
      break;
    default:
      break;
  }
}

}  // namespace opencnc::control
