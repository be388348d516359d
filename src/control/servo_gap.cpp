// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, the EDM stage: between the interpolator and the coupling, the gap servo moves the
// electrode along the programmed path by the gap voltage (backward along the path memory as well),
// the jump lifts it, the orbit moves it around the tool axis (control/gap_servo.hpp, docs/edm.md).
#include "opencnc/control/servo.hpp"

namespace opencnc::control {

// The jump's and the servo's acceleration: the tool axis' limit (the orbit's and the path's
// axes are within theirs at the speeds a condition may have: read_edm.cpp checks them).
void Servo::configure_gap_servo() noexcept {
  const int j = joint_of(config_.edm.tool_axis);
  const double accel = j >= 0 ? config_.joints[static_cast<std::size_t>(j)].max_acceleration : 0.0;
  gap_.configure(config_.edm, config_.period_s, 0.9 * accel);  // room for the rounding of steps
}

// Only while a program runs: the stage reads the interpolator's head (the path as programmed)
// and puts the electrode's position in its place; the interpolator goes on only when the
// electrode stands at its head and the gap lets it (feed_scale, read by program_inputs).
void Servo::run_gap_servo() noexcept {
  if (!gap_.enabled() || activity_ != Activity::Program) return;
  const traj::MotionBlock* b = block(tick_out_.block_seq);
  const bool marker = b == nullptr || b->kind == traj::BlockKind::Marker;
  GapInputs in;
  in.hold = hold_ || aborting_ || power_stop_;
  in.head = tick_out_.position;
  in.new_block = tick_out_.block_seq != gap_block_;
  gap_block_ = tick_out_.block_seq;
  in.head_feed = marker ? 0.0 : b->feed;
  in.rapid = !marker && b->feed_class == traj::FeedClass::Rapid;
  in.gap_voltage_v = in_.process.gap_voltage_v;
  in.gap_state = in_.process.gap_state;
  const Pose p = gap_.step(in);
  for (int j = 0; j < config_.joint_count; ++j) {
    const int axis = config_.joints[static_cast<std::size_t>(j)].axis;
    if (!manual(j)) commanded_[axis] = p[axis];
  }
  watch_gap();
}

// What the gap servo cannot mend itself: backing off has run out of path (told, the servo holds
// there), and a short that outlasts the condition's short_timeout_s (a fault: the generator and
// the drives off, the run ended), and a finishing cycle whose orbit has not reached its size
// within the condition's finish_timeout_s (a fault as well: the cavity would stay undersize).
void Servo::watch_gap() noexcept {
  const EdmStatus& s = gap_.status();
  if (gap_.reached_retract_limit()) {
    ServoEvent e;
    e.kind = EventKind::EdmRetractLimit;
    e.run_id = run_id_;
    e.action = static_cast<std::uint32_t>(s.condition);
    e.value = s.backlog_mm;
    emit(e);
  }
  if (gap_.short_timed_out())
    enter_fault({FaultKind::EdmShort, static_cast<std::int8_t>(s.condition), s.short_s,
                 gap_.condition().short_timeout_s, tick_});
  else if (gap_.finish_timed_out())
    enter_fault({FaultKind::EdmFinishTimeout, static_cast<std::int8_t>(s.condition), gap_.orbit_radius_mm(),
                 gap_.condition().finish_timeout_s, tick_});
}

}  // namespace opencnc::control
