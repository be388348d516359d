// SPDX-License-Identifier: GPL-3.0-or-later
// JointHoming: one joint's homing phases, edge latching and the move to the home position.
#include "opencnc/control/homing.hpp"

namespace opencnc::control {

namespace {

bool same_direction(double a, double b) noexcept {
  return (a > 0) == (b > 0);
}

}  // namespace

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
  const bool decel_home = c.method == HomeMethod::DecelHome;
  switch (phase_) {
    case HomingPhase::Idle:
    case HomingPhase::Done:
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

}  // namespace opencnc::control
