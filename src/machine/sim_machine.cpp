// SPDX-License-Identifier: GPL-3.0-or-later
// SimMachine: one servo period = latch outputs, integrate joints and spindle in fixed
// sub-steps, update the power supply and auxiliaries, sample the inputs.
#include "opencnc/machine/sim_machine.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::machine {

namespace {

/// Regenerated energy lifts the DC link until the brake chopper burns it off at this ratio
/// of the nominal voltage.
constexpr double kBrakeChopperRatio = 1.15;

/// Whole periods a delay takes (at least one: the acknowledgement comes with a later sample
/// than the request at the earliest).
std::uint64_t periods_for(double delay_s, double period_s) {
  const double n = std::ceil(delay_s / period_s - 1e-9);
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::max(0.0, n)));
}

std::uint64_t low_bits(int n) {
  return n >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n) - 1;
}

}  // namespace

SimMachine::SimMachine(const SimMachineConfig& config) : config_(config), rng_(config.seed) {
  for (int j = 0; j < config.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    joints_[uj] = SimJoint(config.joints[uj], config.servo_period_s, config.substeps, config.linear_periods);
  }
  if (config.spindle)
    spindle_ =
        SimSpindle(config.spindle_config, config.servo_period_s, config.substeps, config.linear_periods);
  if (config.probe.joint >= 0) {
    probe_ = SimSwitch(config.probe.trip, config.probe.hysteresis, config.probe.noise);
    probe_table_ = joints_[static_cast<std::size_t>(config.probe.joint)].table_position();
  }
  if (config.probe.sphere.present) sphere_ = SimSphereProbe(config.probe.sphere);
  for (std::size_t k = 0; k < input_switches_.size(); ++k) {
    const SimInputSwitch& in = config.input_switches[k];
    if (in.channel >= 0 && in.joint >= 0) input_switches_[k] = SimSwitch(in.window, in.hysteresis, in.noise);
  }
  if (config.broach.present) broach_ = SimBroachLoad(config.broach, config.seed);
  temperature_c_ = config.temperature_c;
  if (config.edm.present) edm_.configure(config.edm, config.servo_period_s);
  if (config.plasma.present) plasma_.configure(config.plasma, config.servo_period_s);
  mount(0);  // the spindle holds tool 0 (or its simulated electrode) until a change
  analog_in_ = config.analog_in;
  dc_link_v_ = config.power.dc_link_nominal_v;
  ups_periods_left_ =
      config.power.ups
          ? static_cast<std::uint64_t>(std::llround(config.power.ups_runtime_s / config.servo_period_s))
          : 0;
  arc_needed_ = periods_for(config.process.arc_delay_s, config.servo_period_s);
  prepare_needed_ = periods_for(config.tool_changer.prepare_time_s, config.servo_period_s);
  change_needed_ = periods_for(config.tool_changer.change_time_s, config.servo_period_s);
  sample();
}

MachineCapabilities SimMachine::capabilities() const noexcept {
  MachineCapabilities c;
  c.joint_count = config_.joint_count;
  for (int j = 0; j < config_.joint_count; ++j)
    c.joints[static_cast<std::size_t>(j)] = joint(j).capabilities();
  c.spindle = config_.spindle;
  c.spindle_encoder = config_.spindle && config_.spindle_config.encoder_counts_per_rev > 0;
  c.spindle_orient = config_.spindle && config_.spindle_config.orient;
  c.spindle_torque = config_.spindle;
  c.power_monitor = config_.power_monitor;
  c.ups = config_.power_monitor && config_.power.ups;
  c.probe = config_.probe.joint >= 0 || config_.probe.sphere.present;
  c.tool_changer = config_.tool_changer.present;
  c.torch = config_.process.torch;
  c.generator = config_.process.generator;
  c.digital_inputs = config_.digital_inputs;
  c.digital_outputs = config_.digital_outputs;
  c.analog_inputs = config_.analog_inputs;
  c.analog_outputs = config_.analog_outputs;
  c.handwheel = config_.handwheel;
  return c;
}

void SimMachine::set_hand_target(int joint, double target, double speed) noexcept {
  if (joint >= 0 && joint < config_.joint_count)
    joints_[static_cast<std::size_t>(joint)].set_hand_target(target, speed);
}

void SimMachine::turn_handwheel(std::int32_t counts) noexcept {
  if (config_.handwheel) handwheel_count_ += static_cast<std::uint32_t>(counts);
}

void SimMachine::read(MachineInputs& in) noexcept {
  in = inputs_;
}

void SimMachine::write(const MachineOutputs& out) noexcept {
  // What the next periods need of the outputs; the joints and the spindle latch their own.
  estop_release_ = out.estop_release;
  process_ = out.process;
  digital_out_ = out.digital_out;
  tool_ = out.tool;
  advance(out);
  ++inputs_.cycle;
  sample();
}

bool SimMachine::drives_powered() const noexcept {
  return !estop_pressed_ && estop_release_ && !undervoltage_;
}

void SimMachine::set_amp_fault(int joint, bool fault) noexcept {
  if (joint >= 0 && joint < config_.joint_count) joints_[static_cast<std::size_t>(joint)].set_fault(fault);
}

void SimMachine::set_external_effort(int joint, double effort) noexcept {
  if (joint >= 0 && joint < config_.joint_count) external_effort_[static_cast<std::size_t>(joint)] = effort;
}

void SimMachine::set_digital_input(int channel, bool value) noexcept {
  if (channel < 0 || channel >= kDigitalChannels) return;
  const std::uint64_t bit = std::uint64_t{1} << channel;
  digital_in_ = value ? (digital_in_ | bit) : (digital_in_ & ~bit);
}

void SimMachine::set_analog_input(int channel, double value) noexcept {
  if (channel < 0 || channel >= kAnalogChannels) return;
  analog_in_[static_cast<std::size_t>(channel)] = value;
  analog_rate_[static_cast<std::size_t>(channel)] = 0;
}

void SimMachine::drift_analog_input(int channel, double target, double units_per_s) noexcept {
  if (channel < 0 || channel >= kAnalogChannels) return;
  analog_target_[static_cast<std::size_t>(channel)] = target;
  analog_rate_[static_cast<std::size_t>(channel)] = std::fabs(units_per_s);
}

void SimMachine::advance(const MachineOutputs& out) noexcept {
  const bool powered = drives_powered();
  const int n = config_.joint_count;
  bool substeps = false;  // begin_period() integrates what it can at once
  for (int j = 0; j < n; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const double cutting = config_.broach.load_on_stroke && j == config_.broach.stroke_joint
                               ? broach_.stroke_force_n()
                               : 0.0;  // the chip resists the stroke (last period's)
    joints_[uj].begin_period(out.joints[uj], powered && !undervoltage_fault_[uj],
                             external_effort_[uj] + cutting);
    substeps = substeps || joints_[uj].needs_substeps();
  }
  if (config_.spindle) {
    spindle_.begin_period(out.spindle, powered);
    substeps = substeps || spindle_.needs_substeps();
  }
  // Sub-steps outside, joints inside: the joints' dependency chains are independent, so the
  // CPU overlaps them (measured: about twice as fast as one joint after the other).
  for (int i = 0; substeps && i < config_.substeps; ++i) {
    for (int j = 0; j < n; ++j) joints_[static_cast<std::size_t>(j)].substep(i);
    if (config_.spindle) spindle_.substep();
  }
  for (int j = 0; j < n; ++j) joints_[static_cast<std::size_t>(j)].end_period();
  if (config_.spindle) spindle_.end_period();
  update_power(out);
  update_auxiliaries();
  update_broach();
  if (config_.edm.present) step_edm();
  if (config_.plasma.present) step_plasma();
}

// The plate and the arc see the torch where the joints' tables are.
void SimMachine::step_plasma() noexcept {
  const SimPlasmaConfig& p = config_.plasma;
  const auto table = [&](int j) {
    return j >= 0 && j < config_.joint_count ? joints_[static_cast<std::size_t>(j)].table_position() : 0.0;
  };
  const bool torch = config_.process.torch && process_.torch_on;
  const bool oxygen = p.cut_oxygen_output >= 0 && ((digital_out_ >> p.cut_oxygen_output) & 1u) != 0;
  plasma_.step(table(p.x_joint), table(p.y_joint), table(p.z_joint), torch, torch && oxygen);
}

// The cutter's position from the joints' tables: where the chip is cut, not where the encoders say.
void SimMachine::update_broach() noexcept {
  const SimBroachConfig& b = config_.broach;
  if (!b.present) return;
  const SimJoint& stroke = joints_[static_cast<std::size_t>(b.stroke_joint)];
  broach_.update(stroke.table_position(), stroke.velocity(),
                 joints_[static_cast<std::size_t>(b.rotary_joint)].table_position(),
                 joints_[static_cast<std::size_t>(b.radial_joint)].table_position());
}

// The spark gap sees the true electrode's tip: the feed joint's table less the electrode's offset
// along it (and across the tool axis the lateral joints' less theirs), the work turned by the
// orientation joints (B, C), and the generator's outputs of this period.
void SimMachine::step_edm() noexcept {
  const SimEdmConfig& e = config_.edm;
  const auto table = [&](int j) {
    return j >= 0 && j < config_.joint_count ? joints_[static_cast<std::size_t>(j)].table_position() : 0.0;
  };
  const auto offset = [&](int axis) {
    return axis >= 0 ? electrode_.offset[static_cast<std::size_t>(axis)] : 0.0;
  };
  SimEdmPose pose;
  pose.feed = table(e.joint) - offset(e.offset_axis);
  for (int i = 0; i < 2; ++i) {
    pose.orientation[i] = table(e.orientation_joints[i]);
    pose.lateral[i] = table(e.lateral_joints[i]) - offset(e.lateral_offset_axes[i]);
  }
  edm_.step(pose, config_.process.generator && process_.generator_on, process_.generator, rng_);
}

// A tool change puts `tool`'s true electrode in: the spark gap burns with it (and its own wear),
// the reference sphere is touched with it.
void SimMachine::mount(std::int32_t tool) noexcept {
  mounted_tool_ = tool;
  electrode_ = SimElectrode{tool, {}, 0};
  for (int k = 0; k < config_.electrode_count; ++k)
    if (config_.electrodes[static_cast<std::size_t>(k)].tool == tool)
      electrode_ = config_.electrodes[static_cast<std::size_t>(k)];
  if (config_.edm.present) edm_.mount(tool);
}

void SimMachine::replace_electrode(std::int32_t tool, const Vec3& offset, double tip_radius) noexcept {
  int k = 0;
  while (k < config_.electrode_count && config_.electrodes[static_cast<std::size_t>(k)].tool != tool) ++k;
  if (k == kMaxSimElectrodes) return;
  if (k == config_.electrode_count) ++config_.electrode_count;
  config_.electrodes[static_cast<std::size_t>(k)] = SimElectrode{tool, offset, tip_radius};
  if (config_.edm.present) edm_.replace(tool);
  if (tool == mounted_tool_) electrode_ = config_.electrodes[static_cast<std::size_t>(k)];
}

// The mounted electrode's offsets as the sphere sees them: shorter along the tool axis by its wear.
Vec3 SimMachine::worn_offset() const noexcept {
  Vec3 o = electrode_.offset;
  const SimEdmConfig& e = config_.edm;
  if (e.present && e.offset_axis >= 0)
    o[static_cast<std::size_t>(e.offset_axis)] += e.work_direction * edm_.electrode_wear_mm();
  return o;
}

// Mains on: the rectifier holds the DC link at nominal. Mains off: a charged UPS keeps the
// control going (and holds the link too only if it is built to); otherwise the link capacitor
// alone feeds the idle load and the axes: ½·C·V² loses idle_power·T + E_axes per period
// (braking axes give energy back).
void SimMachine::update_power(const MachineOutputs& out) noexcept {
  const SimPowerConfig& p = config_.power;
  const double period = config_.servo_period_s;
  on_battery_ = !mains_ok_ && ups_periods_left_ > 0;
  if (mains_ok_) {
    dc_link_v_ = p.dc_link_nominal_v;
  } else if (on_battery_ && p.ups_holds_dc_link) {
    --ups_periods_left_;
    dc_link_v_ = p.dc_link_nominal_v;
  } else {
    if (on_battery_) --ups_periods_left_;
    double energy_j = 0;  // what the axes took from the link in this period
    for (int j = 0; j < config_.joint_count; ++j) energy_j += joints_[static_cast<std::size_t>(j)].energy_j();
    const double c = p.dc_link_capacitance_f;
    const double stored_j = 0.5 * c * dc_link_v_ * dc_link_v_ - p.idle_power_w * period - energy_j;
    dc_link_v_ =
        std::min(std::sqrt(std::max(0.0, 2.0 * stored_j / c)), kBrakeChopperRatio * p.dc_link_nominal_v);
  }
  undervoltage_ = dc_link_v_ < p.dc_link_min_v;
  // A drive that sees undervoltage while enabled latches the fault until it is disabled.
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    const bool enabled = out.joints[uj].enable;
    if (undervoltage_ && enabled) undervoltage_fault_[uj] = true;
    if (!enabled && !undervoltage_) undervoltage_fault_[uj] = false;
  }
}

void SimMachine::update_auxiliaries() noexcept {
  const bool changer = config_.tool_changer.present;
  prepare_periods_ = changer && tool_.prepare ? prepare_periods_ + 1 : 0;
  change_periods_ = changer && tool_.change ? change_periods_ + 1 : 0;
  arc_periods_ = config_.process.torch && process_.torch_on && arc_available_ ? arc_periods_ + 1 : 0;
  const bool changed = changer && tool_.change && change_periods_ >= change_needed_;
  if (changed && !tool_changed_) mount(tool_.prepare_tool);
  tool_changed_ = changed;
  for (std::size_t k = 0; k < analog_in_.size(); ++k) {
    if (analog_rate_[k] == 0) continue;
    const double step = analog_rate_[k] * config_.servo_period_s, gap = analog_target_[k] - analog_in_[k];
    analog_in_[k] = std::fabs(gap) <= step ? analog_target_[k] : analog_in_[k] + std::copysign(step, gap);
    if (analog_in_[k] == analog_target_[k]) analog_rate_[k] = 0;
  }
}

void SimMachine::sample() noexcept {
  inputs_.estop_ok = !estop_pressed_;
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    previous_feedback_[uj] = inputs_.joints[uj].position;
    joints_[uj].sample(inputs_.joints[uj], rng_, temperature_c_);
    inputs_.joints[uj].amp_fault = inputs_.joints[uj].amp_fault || undervoltage_fault_[uj];
  }
  inputs_.power.mains_ok = mains_ok_;
  inputs_.power.ups_on_battery = on_battery_;
  inputs_.power.dc_link_v = dc_link_v_;
  if (config_.spindle) spindle_.sample(inputs_.spindle);
  if (config_.probe.joint >= 0) sample_probe();
  if (config_.probe.sphere.present) sample_sphere_probe();
  inputs_.process.arc_ok = arc_periods_ >= arc_needed_;
  inputs_.process.gap_voltage_v = config_.process.generator && process_.generator_on ? gap_voltage_v_ : 0.0;
  if (config_.edm.present) edm_.sample(inputs_.process);
  inputs_.tool.prepared = prepare_periods_ >= prepare_needed_;
  inputs_.tool.changed = change_periods_ >= change_needed_;
  std::uint64_t switched = 0;  // inputs wired to switches on the machine
  for (std::size_t k = 0; k < input_switches_.size(); ++k) {
    const SimInputSwitch& w = config_.input_switches[k];
    if (w.channel < 0 || w.joint < 0 || w.joint >= config_.joint_count || w.channel >= kDigitalChannels)
      continue;
    if (input_switches_[k].update(joints_[static_cast<std::size_t>(w.joint)].table_position(), rng_))
      switched |= std::uint64_t{1} << w.channel;
  }
  inputs_.digital_in = (digital_in_ | switched) & low_bits(config_.digital_inputs);
  inputs_.handwheel_count = static_cast<std::int32_t>(handwheel_count_);
  for (int k = 0; k < kAnalogChannels; ++k) {
    inputs_.analog_in[static_cast<std::size_t>(k)] =
        k < config_.analog_inputs ? analog_in_[static_cast<std::size_t>(k)] : 0.0;
  }
  if (config_.broach.present)
    inputs_.analog_in[static_cast<std::size_t>(config_.broach.load_input)] = broach_.load_kn();
  if (config_.plasma.present) plasma_.sample(inputs_);
}

void SimMachine::sample_probe() noexcept {
  // The encoders are latched where the table crossed the switching point, as a probe latch
  // input does in hardware: between the last two samples, in proportion.
  const double before = probe_table_,
               now = joints_[static_cast<std::size_t>(config_.probe.joint)].table_position();
  const bool was = inputs_.probe;
  inputs_.probe = probe_.update(now, rng_);
  if (inputs_.probe != was) {
    const double f = now != before ? std::clamp((probe_.edge() - before) / (now - before), 0.0, 1.0) : 1.0;
    for (int j = 0; j < config_.joint_count; ++j) {
      const auto uj = static_cast<std::size_t>(j);
      inputs_.probe_latch[uj] =
          previous_feedback_[uj] + f * (inputs_.joints[uj].position - previous_feedback_[uj]);
    }
    ++inputs_.probe_edges;
  }
  probe_table_ = now;
}

// The electrode against the reference sphere: the encoders latched where the contact changed,
// in proportion between the last two samples (the gap changes smoothly over one period).
void SimMachine::sample_sphere_probe() noexcept {
  Vec3 p{};
  for (std::size_t k = 0; k < 3; ++k) {
    const int j = config_.probe.sphere.joints[k];
    p[k] = j >= 0 ? joints_[static_cast<std::size_t>(j)].table_position() : 0.0;
  }
  const int b = config_.probe.sphere.b_joint;
  if (b >= 0 && b < config_.joint_count) sphere_.turn(joints_[static_cast<std::size_t>(b)].table_position());
  sphere_.set_electrode(worn_offset(), electrode_.tip_radius);
  const bool was = inputs_.probe;
  inputs_.probe = sphere_.update(p, rng_);
  if (inputs_.probe == was) return;
  const double f = sphere_.edge_fraction();
  for (int j = 0; j < config_.joint_count; ++j) {
    const auto uj = static_cast<std::size_t>(j);
    inputs_.probe_latch[uj] =
        previous_feedback_[uj] + f * (inputs_.joints[uj].position - previous_feedback_[uj]);
  }
  ++inputs_.probe_edges;
}

}  // namespace opencnc::machine
