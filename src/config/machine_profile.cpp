// SPDX-License-Identifier: GPL-3.0-or-later
// MachineProfile lookups and the simulated machine a profile describes.
#include "opencnc/config/machine_profile.hpp"

#include <algorithm>
#include <cmath>

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
    j.stall_detector = a.stall_detector;
  }
  for (std::size_t k = 0; k < profile.sim_input_switches.size() && k < c.input_switches.size(); ++k)
    c.input_switches[k] = profile.sim_input_switches[k];
  c.handwheel = profile.handwheel.present;
  c.temperature_c = profile.sim_temperature_c;
  c.spindle = profile.spindle.present;
  c.spindle_config = profile.spindle.sim;
  c.power_monitor = profile.power.monitor;
  c.power = profile.power.sim;
  if (profile.probe.present && profile.probe.sim_joint >= 0) {
    c.probe.joint = profile.probe.sim_joint;
    c.probe.trip = profile.probe.sim_trip;
    c.probe.hysteresis = profile.probe.sim_hysteresis;
    c.probe.noise = profile.probe.sim_noise;
  }
  const ReferenceSphereProfile& sphere = profile.probe.reference_sphere;
  if (sphere.present && sphere.sim) {
    machine::SimSphereTarget& t = c.probe.sphere;
    t.present = true;
    for (const AxisProfile& a : profile.axes) {
      if (index(a.axis) < 3) t.joints[static_cast<std::size_t>(index(a.axis))] = a.joint;
    }
    t.centre = {sphere.position[0], sphere.position[1], sphere.position[2]};
    t.radius = sphere.diameter / 2;
    t.hysteresis = sphere.sim_hysteresis;
    if (sphere.sim_turns_with_b && profile.find(Axis::B) != nullptr) {
      t.b_joint = profile.find(Axis::B)->joint;
      t.b_axis = sphere.sim_b_axis;
      t.b_direction = sphere.sim_b_direction;
      t.b_at_centre_deg = sphere.b_deg;
    }
    t.noise = sphere.sim_noise;
  }
  c.tool_changer = profile.tool_changer_sim;
  c.process = profile.process;
  if (profile.broaching.sim.present) {  // the bore on the coupling's axes (the reader checked them)
    c.broach = profile.broaching.sim;
    const auto joint = [&](Axis a) { return profile.find(a) != nullptr ? profile.find(a)->joint : -1; };
    c.broach.stroke_joint = joint(profile.coupling.master);
    c.broach.rotary_joint = joint(profile.coupling.slave);
    c.broach.radial_joint = joint(profile.broaching.radial);
    c.broach.present = c.broach.stroke_joint >= 0 && c.broach.rotary_joint >= 0 && c.broach.radial_joint >= 0;
  }
  c.edm = profile.edm.sim;
  if (profile.plasma.sim.present) {  // the plate under the torch's axes (the reader checked them)
    c.plasma = profile.plasma.sim;
    const auto joint = [&](Axis a) { return profile.find(a) != nullptr ? profile.find(a)->joint : -1; };
    c.plasma.x_joint = static_cast<std::int8_t>(joint(Axis::X));
    c.plasma.y_joint = static_cast<std::int8_t>(joint(Axis::Y));
    c.plasma.z_joint = static_cast<std::int8_t>(joint(Axis::Z));
    c.plasma.present = c.plasma.x_joint >= 0 && c.plasma.y_joint >= 0 && c.plasma.z_joint >= 0;
  }
  for (const machine::SimElectrode& e : profile.sim_electrodes)  // the reader kept them within the array
    if (c.electrode_count < machine::kMaxSimElectrodes)
      c.electrodes[static_cast<std::size_t>(c.electrode_count++)] = e;
  c.digital_inputs = profile.io.digital_inputs;
  c.digital_outputs = profile.io.digital_outputs;
  c.analog_inputs = profile.io.analog_inputs;
  c.analog_outputs = profile.io.analog_outputs;
  c.analog_in = profile.alarms.sim_values;
  return c;
}

MotionReserve compensation_reserve(const AxisProfile& axis, double servo_period_s) {
  const CompensationProfile& c = axis.compensation;
  if (!c.present) return {};
  double slope = 0, bend = 0;  // largest |dE/dx| and largest change of it at a point
  for (const std::vector<double>* table : {&c.forward, &c.reverse}) {
    double last = 0;
    for (std::size_t i = 0; i + 1 < c.positions.size() && i + 1 < table->size(); ++i) {
      const double k = ((*table)[i + 1] - (*table)[i]) / (c.positions[i + 1] - c.positions[i]);
      slope = std::max(slope, std::abs(k));
      bend = std::max(bend, std::abs(k - last));  // the first point bends from the flat end
      last = k;
    }
    bend = std::max(bend, std::abs(last));  // and the last one into the flat end beyond
  }
  MotionReserve r;
  r.velocity = c.takeup_velocity + slope * axis.max_velocity;
  r.acceleration =
      c.takeup_acceleration + slope * axis.max_acceleration + bend * axis.max_velocity / servo_period_s;
  return r;
}

}  // namespace opencnc::config
