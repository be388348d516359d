// SPDX-License-Identifier: GPL-3.0-or-later
// MachineIO over HAL pins: inputs from the pins, outputs to them, capabilities clipped to the pins.
#include "opencnc/hal/hal_machine.hpp"

#include <algorithm>

namespace opencnc::hal {

void HalMachine::set_capabilities(const machine::MachineCapabilities& caps) noexcept {
  caps_ = caps;
  const MachinePins& p = *pins_;
  caps_.joint_count = std::min(caps.joint_count, p.joint_count);
  caps_.digital_inputs = std::min(caps.digital_inputs, p.digital_inputs);
  caps_.digital_outputs = std::min(caps.digital_outputs, p.digital_outputs);
  caps_.analog_inputs = std::min(caps.analog_inputs, p.analog_inputs);
  caps_.analog_outputs = std::min(caps.analog_outputs, p.analog_outputs);
  caps_.power_monitor = true;  // the power-fail pin
  caps_.ups = false;
  for (auto& j : caps_.joints) {
    j.effort = j.effort && p.effort_wired;
    j.home_level = j.stall_detect = false;  // no pins for them
  }
  caps_.spindle_torque = caps_.spindle && caps.spindle_torque && p.effort_wired;
  index_armed_ = {};
}

void HalMachine::read(machine::MachineInputs& in) noexcept {
  const MachinePins& p = *pins_;
  in.cycle = ++cycle_;
  for (int j = 0; j < caps_.joint_count; ++j) read_joint(j, in.joints[static_cast<std::size_t>(j)]);
  in.estop_ok = *p.estop_in;
  in.power.mains_ok = !*p.power_fail;
  in.power.ups_on_battery = false;
  read_spindle(in.spindle);
  in.probe = caps_.probe && *p.probe_in;  // no latch pins: the servo estimates the edge itself
  in.tool.prepared = caps_.tool_changer && *p.tool_prepared;
  in.tool.changed = caps_.tool_changer && *p.tool_changed;
  std::uint64_t din = 0;
  for (int i = 0; i < caps_.digital_inputs; ++i)
    if (*p.digital_in[static_cast<std::size_t>(i)]) din |= std::uint64_t{1} << i;
  in.digital_in = din;
  for (int i = 0; i < caps_.analog_inputs; ++i)
    in.analog_in[static_cast<std::size_t>(i)] = *p.analog_in[static_cast<std::size_t>(i)];
  in.handwheel_count = caps_.handwheel ? *p.handwheel_counts : 0;
}

// The encoder zeroes its count at the index mark and clears index-enable: the mark lies where the
// joint would be now, extrapolated at its last velocity, less the distance counted since. The
// feedback stays continuous from there (docs/hal.md: index marks).
void HalMachine::read_joint(int j, machine::JointInputs& in) noexcept {
  const auto uj = static_cast<std::size_t>(j);
  const JointPins& p = pins_->joints[uj];
  const double raw = *p.pos_fb;
  if (caps_.joints[uj].index && index_armed_[uj] && !*p.index_enable) {
    const double mark = last_position_[uj] + last_velocity_[uj] * period_s_ - raw;
    fb_offset_[uj] = mark;
    index_position_[uj] = mark;
    ++index_count_[uj];
    index_armed_[uj] = false;
  }
  const double position = raw + fb_offset_[uj];
  last_velocity_[uj] = cycle_ > 1 ? (position - last_position_[uj]) / period_s_ : 0;
  last_position_[uj] = position;
  in.position = position;
  in.velocity = last_velocity_[uj];
  in.index_count = index_count_[uj];
  in.index_position = index_position_[uj];
  const std::uint8_t sw = caps_.joints[uj].switches;
  in.amp_fault = *p.amp_fault;
  in.home = (sw & machine::kSwitchHome) != 0 && *p.home_sw;
  in.limit_neg = (sw & machine::kSwitchLimitNeg) != 0 && *p.limit_min;
  in.limit_pos = (sw & machine::kSwitchLimitPos) != 0 && *p.limit_max;
  in.effort = caps_.joints[uj].effort ? *p.effort : 0.0;
}

void HalMachine::read_spindle(machine::SpindleInputs& in) noexcept {
  const MachinePins& p = *pins_;
  if (!caps_.spindle) return;
  in.speed_rpm = *p.spindle_speed_in;
  in.position_rev = *p.spindle_revs;
  in.at_speed = *p.spindle_at_speed;
  in.orient_done = caps_.spindle_orient && *p.spindle_orient_done;
  in.fault = *p.spindle_fault;
  in.torque_nm = caps_.spindle_torque ? *p.spindle_torque : 0.0;
}

void HalMachine::write(const machine::MachineOutputs& out) noexcept {
  const MachinePins& p = *pins_;
  for (int j = 0; j < caps_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const JointPins& jp = p.joints[uj];
    const machine::JointOutputs& o = out.joints[uj];
    *jp.pos_cmd = o.position - fb_offset_[uj];  // back into the encoder's (re-zeroed) frame
    *jp.vel_cmd = o.velocity_ff;
    *jp.step_cmd = static_cast<std::int32_t>(static_cast<std::uint32_t>(o.step_position & 0xffffffff));
    *jp.enable = o.enable;
    if (caps_.joints[uj].index && o.enable && !index_armed_[uj]) {
      *jp.index_enable = true;
      index_armed_[uj] = true;
    }
  }
  *p.estop_out = out.estop_release;
  const bool turning = caps_.spindle && out.spindle.direction != machine::SpindleDirection::Stopped;
  const bool cw = out.spindle.direction == machine::SpindleDirection::Clockwise;
  *p.spindle_on = turning;
  *p.spindle_forward = turning && cw;
  *p.spindle_reverse = turning && !cw;
  *p.spindle_speed_out = turning ? (cw ? out.spindle.speed_rpm : -out.spindle.speed_rpm) : 0.0;
  *p.spindle_orient = caps_.spindle_orient && out.spindle.orient;
  *p.spindle_orient_angle = out.spindle.orient_angle_deg;
  *p.flood = out.process.flood;
  *p.mist = out.process.mist;
  *p.tool_prepare_number = out.tool.prepare_tool;
  *p.tool_prepare = caps_.tool_changer && out.tool.prepare;
  *p.tool_change = caps_.tool_changer && out.tool.change;
  for (int i = 0; i < caps_.digital_outputs; ++i)
    *p.digital_out[static_cast<std::size_t>(i)] = ((out.digital_out >> i) & 1u) != 0;
  for (int i = 0; i < caps_.analog_outputs; ++i)
    *p.analog_out[static_cast<std::size_t>(i)] = out.analog_out[static_cast<std::size_t>(i)];
}

}  // namespace opencnc::hal
