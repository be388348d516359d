// SPDX-License-Identifier: GPL-3.0-or-later
// The replay filter's held-back machine state and its restoration at the first live segment.
#include "opencnc/canon/replay_filter.hpp"

namespace opencnc::canon {

bool ReplayFilter::motion(SegmentId id, const Pose* end, bool end_unknown) {
  if (live_) return true;
  if (id < first_) {
    if (end != nullptr) at_ = *end;
    at_known_ = end != nullptr || (at_known_ && !end_unknown);
    return false;
  }
  live_ = true;
  if (coupling_.law != 0) next_->set_axis_coupling(coupling_);
  // The machine as the program had left it before segment k: spindles, coolant, outputs. Each
  // is repeated once, in this order, before the first move.
  for (const auto& [index, s] : spindles_) {
    if (s.speed_set) next_->set_spindle_speed(index, s.speed);
    if (s.direction == 1) next_->start_spindle_clockwise(index);
    if (s.direction == -1) next_->start_spindle_counterclockwise(index);
    if (s.direction == 0) next_->stop_spindle_turning(index);
  }
  if (mist_ == 1) next_->mist_on();
  if (flood_ == 1) next_->flood_on();
  for (const auto& [index, v] : digital_) {
    if (v.second) {
      v.first != 0 ? next_->set_motion_output_bit(index) : next_->clear_motion_output_bit(index);
    } else {
      v.first != 0 ? next_->set_aux_output_bit(index) : next_->clear_aux_output_bit(index);
    }
  }
  for (const auto& [index, v] : analog_) next_->set_aux_output_value(index, v);
  for (const ProcessCode& c : process_) next_->process_code(c);  // last: the process on
  return true;
}

void ReplayFilter::process_code(const ProcessCode& c) {
  if (live_) return next_->process_code(c);
  if (c.group == 0) return;
  std::erase_if(process_, [&](const ProcessCode& held) { return held.group == c.group; });
  process_.push_back(c);
}

// Only the coupling that holds at segment k matters: every code before it replaces the one before
// (M175 releases it); it is passed on at k with the origin it had.
void ReplayFilter::set_axis_coupling(const AxisCoupling& c) {
  if (live_) return next_->set_axis_coupling(c);
  coupling_ = c;
  coupling_.has_origin = at_known_;
  coupling_.origin = at_;
}

void ReplayFilter::set_spindle_speed(int spindle, double rpm) {
  if (live_) return next_->set_spindle_speed(spindle, rpm);
  spindles_[spindle].speed = rpm;
  spindles_[spindle].speed_set = true;
}

void ReplayFilter::start_spindle_clockwise(int spindle) {
  if (live_) return next_->start_spindle_clockwise(spindle);
  spindles_[spindle].direction = 1;
}

void ReplayFilter::start_spindle_counterclockwise(int spindle) {
  if (live_) return next_->start_spindle_counterclockwise(spindle);
  spindles_[spindle].direction = -1;
}

void ReplayFilter::stop_spindle_turning(int spindle) {
  if (live_) return next_->stop_spindle_turning(spindle);
  spindles_[spindle].direction = 0;
}

void ReplayFilter::coolant(int& state, bool on, void (Sink::*call)()) {
  if (live_) return (next_->*call)();
  state = on ? 1 : 0;
}

void ReplayFilter::output(int index, int value, bool motion) {
  if (!live_) {
    digital_[index] = {value, motion};
    return;
  }
  if (motion) {
    value != 0 ? next_->set_motion_output_bit(index) : next_->clear_motion_output_bit(index);
  } else {
    value != 0 ? next_->set_aux_output_bit(index) : next_->clear_aux_output_bit(index);
  }
}

}  // namespace opencnc::canon
