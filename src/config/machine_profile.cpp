// SPDX-License-Identifier: GPL-3.0-or-later
// MachineProfile lookups and the simulated machine a profile describes.
#include "opencnc/config/machine_profile.hpp"

namespace opencnc::config {

const AxisProfile* MachineProfile::find(Axis axis) const noexcept {
  for (const AxisProfile& a : axes) {
    if (a.axis == axis) return &a;
  }
  return nullptr;
}

AxisMask MachineProfile::axis_mask() const noexcept {
  AxisMask m;
  for (const AxisProfile& a : axes) m.set(a.axis);
  return m;
}

machine::SimMachineConfig sim_machine_config(const MachineProfile& profile) {
  machine::SimMachineConfig c;
  c.servo_period_s = profile.servo_period_s;
  c.substeps = profile.sim_substeps;
  c.linear_periods = profile.sim_linear_periods;
  c.seed = profile.sim_seed;
  c.joint_count = static_cast<int>(profile.axes.size());
  for (const AxisProfile& a : profile.axes) {
    machine::SimJointConfig& j = c.joints[static_cast<std::size_t>(a.joint)];
    j.drive = a.drive;
    j.rotary = a.rotary;
    j.counts_per_unit = a.counts_per_unit;
    j.model = a.sim;
    j.switches = a.switches;
  }
  c.spindle = profile.spindle.present;
  c.spindle_config = profile.spindle.sim;
  c.power_monitor = profile.power.monitor;
  c.power = profile.power.sim;
  if (profile.probe.present && profile.probe.sim_joint >= 0) {
    c.probe = {profile.probe.sim_joint, profile.probe.sim_trip, profile.probe.sim_hysteresis,
               profile.probe.sim_noise};
  }
  c.tool_changer = profile.tool_changer_sim;
  c.process = profile.process;
  c.digital_inputs = profile.io.digital_inputs;
  c.digital_outputs = profile.io.digital_outputs;
  c.analog_inputs = profile.io.analog_inputs;
  c.analog_outputs = profile.io.analog_outputs;
  return c;
}

}  // namespace opencnc::config
