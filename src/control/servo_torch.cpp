// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, the plasma stage: after the interpolator (and the EDM's stage), before the coupling,
// compensation and the soft limits, the torch stage adds its Z offset to the programmed path —
// the cut's sequence (find the plate, pierce, cut height) and the height control — so the limits
// and the trace see it (control/torch_height.hpp, docs/cutting.md).
#include "opencnc/control/servo.hpp"

namespace opencnc::control {

void Servo::run_torch_height() noexcept {
  if (!torch_.enabled() || activity_ != Activity::Program) return;
  const machine::PlasmaConfig& pc = config_.plasma;
  const int z = pc.z_axis, jz = joint_of(z);
  if (jz < 0) return;
  const traj::MotionBlock* b = block(tick_out_.block_seq);
  const bool feed =
      b != nullptr && b->kind != traj::BlockKind::Marker && b->feed_class != traj::FeedClass::Rapid;
  TorchInputs in;
  in.hold = hold_ || aborting_ || power_stop_;
  in.programmed_z = commanded_[z] - torch_.offset_mm();  // run_program put the last offset on it
  in.measured_z = position_[static_cast<std::size_t>(jz)] + offset_[static_cast<std::size_t>(jz)];
  in.path_velocity = tick_out_.path_velocity;
  in.feed = feed ? b->feed * feed_override_ : 0.0;
  in.arc_voltage_v = in_.analog_in[static_cast<std::size_t>(pc.arc_voltage_input)];
  in.arc_ok = in_.process.arc_ok;
  in.sensor = ((in_.digital_in >> pc.sensor_input) & 1u) != 0;
  in.breakaway = pc.breakaway_input >= 0 && ((in_.digital_in >> pc.breakaway_input) & 1u) != 0;
  in.height_v = in_.analog_in[static_cast<std::size_t>(pc.height_input)];
  commanded_[z] = in.programmed_z + torch_.step(in);
  if (torch_.event_pending()) {
    ServoEvent e;
    e.kind = EventKind::Torch;
    e.run_id = run_id_;
    e.action = static_cast<std::uint32_t>(torch_.event());
    e.value = torch_.event_value();
    e.segment = tick_out_.segment;
    emit(e);
  }
  if (torch_.hold_requested() && !hold_ && !aborting_ && state_ == State::Running) {
    hold_ = true;  // the run stops on its path; a resume pierces again where it stands
    set_state(State::Held);
  }
}

}  // namespace opencnc::control
