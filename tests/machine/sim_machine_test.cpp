// SPDX-License-Identifier: GPL-3.0-or-later
// SimMachine as a MachineIO: determinism, e-stop, power supply, probe, tool changer, torch,
// generic I/O, capabilities.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>

#include "opencnc/machine/sim_machine.hpp"

namespace opencnc::machine {
namespace {

SimMachineConfig machine_config(std::uint64_t seed = 1) {
  SimMachineConfig c;
  c.seed = seed;
  c.joint_count = 3;
  for (int j = 0; j < 3; ++j) {
    SimJointConfig& jc = c.joints[static_cast<std::size_t>(j)];
    jc.counts_per_unit = 10000;
    jc.switches.limit_neg = {true, -kInf, -101};
    jc.switches.limit_pos = {true, 101, kInf};
    jc.switches.home = {true, 50, kInf};
    jc.switches.noise = 0.002;
    jc.model.index_spacing = 10;
  }
  c.spindle = true;
  c.spindle_config.max_rpm = 8000;
  c.spindle_config.encoder_counts_per_rev = 4096;
  c.probe.joint = 2;
  c.probe.trip = {true, -kInf, -5.0};
  c.tool_changer.present = true;
  c.process.torch = true;
  c.process.generator = true;
  c.digital_inputs = 4;
  c.analog_inputs = 2;
  return c;
}

/// Outputs of period k of a test run: X sweeps slowly through the home switch, Y and Z move.
MachineOutputs run_outputs(int k) {
  MachineOutputs out;
  out.estop_release = true;
  const double t = k * 0.001;
  for (auto& j : out.joints) j.enable = true;
  out.joints[0].position = 45 + 10 * std::sin(0.5 * t);
  out.joints[0].velocity_ff = 5 * std::cos(0.5 * t);
  out.joints[1].position = 20 * t;
  out.joints[1].velocity_ff = 20;
  out.joints[2].position = -8 * std::sin(t);
  out.joints[2].velocity_ff = -8 * std::cos(t);
  out.spindle = {2000, SpindleDirection::Clockwise};
  return out;
}

/// FNV-1a over the bits of every field: equal hashes mean bit-identical inputs.
class Fingerprint {
 public:
  void add(double v) { add_bits(std::bit_cast<std::uint64_t>(v)); }
  void add(bool v) { add_bits(v ? 1 : 0); }
  void add_bits(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) {
      h_ ^= (v >> (8 * i)) & 0xFF;
      h_ *= 0x100000001B3ull;
    }
  }
  void add(const MachineInputs& in) {
    add_bits(in.cycle);
    for (const JointInputs& j : in.joints) {
      add(j.position), add(j.velocity), add(j.effort), add_bits(j.index_count), add(j.index_position);
      add(j.amp_fault), add(j.limit_neg), add(j.limit_pos), add(j.home), add(j.decel);
      add(j.home_level), add(j.stall);
    }
    add(in.estop_ok), add(in.power.mains_ok), add(in.power.ups_on_battery), add(in.power.dc_link_v);
    add(in.spindle.position_rev), add(in.spindle.speed_rpm), add_bits(in.spindle.index_count);
    add(in.spindle.index_position_rev), add(in.spindle.at_speed), add(in.spindle.orient_done),
        add(in.spindle.fault);
    add(in.probe), add(in.process.arc_ok), add(in.process.gap_voltage_v), add(in.tool.prepared),
        add(in.tool.changed);
    add_bits(in.digital_in);
    add_bits(static_cast<std::uint32_t>(in.handwheel_count));
    for (double a : in.analog_in) add(a);
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xCBF29CE484222325ull;
};

std::uint64_t run_fingerprint(std::uint64_t seed, int periods, int* home_edges = nullptr) {
  SimMachine m(machine_config(seed));
  Fingerprint fp;
  MachineInputs in;
  bool home = false;
  for (int k = 0; k < periods; ++k) {
    m.read(in);
    fp.add(in);
    if (home_edges && in.joints[0].home != home) ++*home_edges;
    home = in.joints[0].home;
    m.write(run_outputs(k));
  }
  return fp.value();
}

TEST(SimMachine, TwoRunsAreBitIdentical) {
  int edges = 0;
  const std::uint64_t a = run_fingerprint(1, 20000, &edges);
  EXPECT_EQ(a, run_fingerprint(1, 20000));
  EXPECT_GE(edges, 2);                      // the run really crosses a noisy switch
  EXPECT_NE(a, run_fingerprint(2, 20000));  // and the seed drives its noise
}

TEST(SimMachine, FirstReadShowsThePowerUpState) {
  SimMachineConfig c = machine_config();
  c.joints[1].model.start_position = 12.5;
  SimMachine m(c);
  MachineInputs in;
  m.read(in);
  EXPECT_EQ(in.cycle, 0u);
  EXPECT_EQ(in.joints[1].position, 12.5);
  EXPECT_TRUE(in.estop_ok);
  EXPECT_TRUE(in.power.mains_ok);
  EXPECT_EQ(in.power.dc_link_v, 560.0);
  EXPECT_FALSE(m.drives_powered());  // nothing released yet
}

TEST(SimMachine, FollowsCommandsAndCountsVirtualTime) {
  SimMachine m(machine_config());
  MachineInputs in;
  for (int k = 0; k < 3000; ++k) m.write(run_outputs(k));
  m.read(in);
  EXPECT_EQ(in.cycle, 3000u);
  EXPECT_DOUBLE_EQ(m.time_s(), 3.0);
  const MachineOutputs next = run_outputs(3000);
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(in.joints[static_cast<std::size_t>(j)].position,
                next.joints[static_cast<std::size_t>(j)].position, 5e-3)
        << j;
  }
  EXPECT_NEAR(in.spindle.speed_rpm, 2000, 1e-6);
  EXPECT_TRUE(in.spindle.at_speed);
}

MachineOutputs holding() {
  MachineOutputs out;
  out.estop_release = true;
  for (auto& j : out.joints) j.enable = true;
  return out;
}

TEST(SimMachine, EstopRemovesDrivePower) {
  SimMachine m(machine_config());
  MachineOutputs out = holding();
  out.joints[0].position = 1.0;
  out.spindle = {2000, SpindleDirection::Clockwise};
  m.set_estop_pressed(true);
  for (int k = 0; k < 200; ++k) m.write(out);
  MachineInputs in;
  m.read(in);
  EXPECT_FALSE(in.estop_ok);
  EXPECT_EQ(m.joint(0).motor_position(), 0.0);
  EXPECT_EQ(in.spindle.speed_rpm, 0.0);

  m.set_estop_pressed(false);
  out.estop_release = false;  // the controller has not released its own contact
  for (int k = 0; k < 200; ++k) m.write(out);
  m.read(in);
  EXPECT_TRUE(in.estop_ok);
  EXPECT_EQ(m.joint(0).motor_position(), 0.0);

  out.estop_release = true;
  for (int k = 0; k < 300; ++k) m.write(out);
  EXPECT_NEAR(m.joint(0).motor_position(), 1.0, 1e-3);
}

// Without a UPS the link capacitor alone feeds the idle load P: ½C(V0² − V²) = P·t, so the
// drives trip at t = C(V0² − Vmin²)/(2P) = 0.002 · (560² − 400²) / 300 = 1.024 s.
TEST(SimMachine, DcLinkRunsDownAfterMainsLoss) {
  SimMachine m(machine_config());
  m.set_mains_ok(false);
  MachineInputs in;
  int tripped_at = -1;
  for (int k = 0; k < 2000 && tripped_at < 0; ++k) {
    m.write(holding());
    m.read(in);
    if (in.joints[0].amp_fault) tripped_at = k + 1;
  }
  EXPECT_NEAR(tripped_at, 1024, 1);
  EXPECT_FALSE(in.power.mains_ok);
  EXPECT_FALSE(in.power.ups_on_battery);
  EXPECT_LT(in.power.dc_link_v, 400.0);
  EXPECT_TRUE(in.joints[2].amp_fault);

  // The fault is latched: mains back is not enough, the drive must be disabled once.
  m.set_mains_ok(true);
  m.write(holding());
  m.read(in);
  EXPECT_EQ(in.power.dc_link_v, 560.0);
  EXPECT_TRUE(in.joints[0].amp_fault);
  MachineOutputs off = holding();
  off.joints[0].enable = false;
  m.write(off);
  m.write(holding());
  m.read(in);
  EXPECT_FALSE(in.joints[0].amp_fault);
  EXPECT_TRUE(in.joints[1].amp_fault);
}

// The usual UPS feeds the control only: it reports its battery while the drives' link drains as
// without it.
TEST(SimMachine, UpsFeedsTheControlWhileTheLinkDrains) {
  SimMachineConfig c = machine_config();
  c.power.ups = true;
  c.power.ups_runtime_s = 0.5;
  SimMachineConfig no_ups = machine_config();
  SimMachine m(c), bare(no_ups);
  m.set_mains_ok(false);
  bare.set_mains_ok(false);
  MachineInputs in, bare_in;
  for (int k = 0; k < 200; ++k) {
    m.write(holding());
    bare.write(holding());
  }
  m.read(in);
  bare.read(bare_in);
  EXPECT_TRUE(in.power.ups_on_battery);
  EXPECT_NEAR(m.ups_remaining_s(), 0.3, 1e-12);
  EXPECT_LT(in.power.dc_link_v, 560.0);
  EXPECT_EQ(in.power.dc_link_v, bare_in.power.dc_link_v);
}

TEST(SimMachine, AUpsBuiltToHoldTheLinkHoldsItForItsRuntime) {
  SimMachineConfig c = machine_config();
  c.power.ups = true;
  c.power.ups_runtime_s = 0.5;
  c.power.ups_holds_dc_link = true;
  SimMachine m(c);
  m.set_mains_ok(false);
  MachineInputs in;
  for (int k = 0; k < 200; ++k) m.write(holding());
  EXPECT_NEAR(m.ups_remaining_s(), 0.3, 1e-12);
  for (int k = 0; k < 300; ++k) m.write(holding());
  m.read(in);
  EXPECT_TRUE(in.power.ups_on_battery);
  EXPECT_EQ(in.power.dc_link_v, 560.0);
  m.write(holding());
  m.read(in);
  EXPECT_FALSE(in.power.ups_on_battery);
  EXPECT_LT(in.power.dc_link_v, 560.0);
}

// Accelerating axes take energy from the link; braking gives it back.
TEST(SimMachine, MovingAxesDrainTheLink) {
  auto link_after = [](bool move) {
    SimMachine m(machine_config());
    m.set_mains_ok(false);
    MachineInputs in;
    for (int k = 0; k < 200; ++k) {
      MachineOutputs out = holding();
      if (move) {
        const double t = (k + 1) * 0.001;
        out.joints[0].position = 0.5 * 1000 * t * t;  // 1 m/s² on 100 kg
        out.joints[0].velocity_ff = 1000 * t;
      }
      m.write(out);
    }
    m.read(in);
    return in.power.dc_link_v;
  };
  const double idle = link_after(false);
  const double moving = link_after(true);
  EXPECT_LT(moving, idle - 0.01);
}

// A process load (broach, cut) shows as drive effort: the velocity loop's integrator takes it.
TEST(SimMachine, ExternalLoadAppearsAsDriveEffort) {
  SimMachine m(machine_config());
  MachineInputs in;
  for (int k = 0; k < 500; ++k) m.write(holding());
  m.read(in);
  const double idle = in.joints[1].effort;
  m.set_external_effort(1, -800.0);  // pushes the table towards −
  for (int k = 0; k < 500; ++k) m.write(holding());
  m.read(in);
  // At rest friction takes anything up to its static value, so the drive carries 800 N ± 50 N.
  EXPECT_NEAR(in.joints[1].effort - idle, 800.0, 50.0);
  EXPECT_NEAR(in.joints[1].position, 0.0, 2e-4);  // and the axis holds its place
}

TEST(SimMachine, SpindleFaultStopsTheSpindle) {
  SimMachine m(machine_config());
  MachineOutputs out = holding();
  out.spindle = {1200, SpindleDirection::Clockwise};
  for (int k = 0; k < 1000; ++k) m.write(out);
  m.set_spindle_fault(true);
  for (int k = 0; k < 100; ++k) m.write(out);
  MachineInputs in;
  m.read(in);
  EXPECT_TRUE(in.spindle.fault);
  EXPECT_FALSE(in.spindle.at_speed);
  EXPECT_NEAR(in.spindle.speed_rpm, 1200 - 2000 * 0.1, 1e-6);  // running down at the ramp limit
}

TEST(SimMachine, ProbeTripsAtTheSurface) {
  SimMachine m(machine_config());
  MachineInputs in;
  double tripped_at = 0;
  for (int k = 0; k < 4000 && tripped_at == 0; ++k) {
    MachineOutputs out = holding();
    out.joints[2].position = -0.002 * k;  // 2 mm/s down
    out.joints[2].velocity_ff = -2;
    m.write(out);
    m.read(in);
    if (in.probe) tripped_at = m.joint(2).table_position();
  }
  EXPECT_NEAR(tripped_at, -5.0, 0.0005 + 0.002);  // noise + one period of travel
}

TEST(SimMachine, ToolChangerAcknowledgesAfterItsTimes) {
  SimMachine m(machine_config());
  MachineOutputs out = holding();
  out.tool.prepare_tool = 7;
  out.tool.prepare = true;
  MachineInputs in;
  for (int k = 0; k < 499; ++k) m.write(out);
  m.read(in);
  EXPECT_FALSE(in.tool.prepared);
  m.write(out);
  m.read(in);
  EXPECT_TRUE(in.tool.prepared);
  out.tool.prepare = false;
  out.tool.change = true;
  m.write(out);
  m.read(in);
  EXPECT_FALSE(in.tool.prepared);
  for (int k = 0; k < 1999; ++k) m.write(out);
  m.read(in);
  EXPECT_TRUE(in.tool.changed);
}

TEST(SimMachine, AToolChangeMountsTheToolsTrueElectrodeInTheGapAndAtTheSphere) {
  SimMachineConfig c = machine_config();
  c.probe.joint = -1;
  c.probe.sphere.present = true;  // far away: only the electrode it sees matters here
  c.probe.sphere.joints = {0, 1, 2};
  c.probe.sphere.centre = {500, 0, 0};
  c.probe.sphere.radius = 5;
  c.edm.present = true;
  c.edm.joint = 2;
  c.edm.offset_axis = 2;
  c.edm.surface_mm = -0.5;  // the work 0.5 mm below the holder at Z 0
  c.edm.noise_v = 0;
  c.electrodes[0] = SimElectrode{5, {0.1, 0.2, 0.3}, 0.8};
  c.electrode_count = 1;
  SimMachine m(c);
  MachineOutputs out = holding();
  out.process.generator_on = true;
  out.process.generator.voltage_v = 100;
  m.write(out);
  EXPECT_EQ(m.mounted_tool(), 0);
  EXPECT_NEAR(m.edm().gap_mm(), 0.5, 1e-9) << "no electrode known: its tip is at the holder";
  out.tool.prepare_tool = 5;
  out.tool.change = true;
  for (int k = 0; k < 2000; ++k) m.write(out);
  EXPECT_EQ(m.mounted_tool(), 5);
  m.write(out);
  EXPECT_NEAR(m.edm().gap_mm(), 0.2, 1e-9) << "tool 5's electrode is 0.3 mm long";
  EXPECT_EQ(m.sphere_probe().offset(), (Vec3{0.1, 0.2, 0.3}));
  EXPECT_EQ(m.sphere_probe().tip_radius(), 0.8);
  // The operator replaces it with a shorter one: the gap and the sphere see it at once.
  m.replace_electrode(5, {0, 0, 0.1}, 0);
  m.write(out);
  EXPECT_NEAR(m.edm().gap_mm(), 0.4, 1e-9);
  EXPECT_EQ(m.sphere_probe().offset(), (Vec3{0, 0, 0.1}));
  EXPECT_EQ(m.electrode().tool, 5);
}

TEST(SimMachine, TorchArcNeedsItsDelayAndGas) {
  SimMachine m(machine_config());
  MachineOutputs out = holding();
  out.process.torch_on = true;
  MachineInputs in;
  for (int k = 0; k < 499; ++k) m.write(out);
  m.read(in);
  EXPECT_FALSE(in.process.arc_ok);
  m.write(out);
  m.read(in);
  EXPECT_TRUE(in.process.arc_ok);
  m.set_arc_available(false);
  m.write(out);
  m.read(in);
  EXPECT_FALSE(in.process.arc_ok);
}

TEST(SimMachine, GenericInputsAndGapVoltage) {
  SimMachine m(machine_config());
  m.set_digital_input(1, true);
  m.set_digital_input(9, true);  // not wired: only 4 inputs
  m.set_analog_input(1, 2.5);
  m.set_analog_input(5, 1.0);  // not wired
  m.set_gap_voltage(80);
  MachineOutputs out = holding();
  m.write(out);
  MachineInputs in;
  m.read(in);
  EXPECT_EQ(in.digital_in, 0b10u);
  EXPECT_EQ(in.analog_in[1], 2.5);
  EXPECT_EQ(in.analog_in[5], 0.0);
  EXPECT_EQ(in.process.gap_voltage_v, 0.0);  // generator off
  out.process.generator_on = true;
  m.write(out);
  m.read(in);
  EXPECT_EQ(in.process.gap_voltage_v, 80.0);
}

TEST(SimMachine, CapabilitiesDescribeTheConfiguration) {
  SimMachineConfig c = machine_config();
  c.joints[1].drive = JointDrive::Stepper;
  c.joints[2].switches.home.present = false;
  const MachineCapabilities caps = SimMachine(c).capabilities();
  EXPECT_EQ(caps.joint_count, 3);
  EXPECT_EQ(caps.joints[0].drive, JointDrive::Servo);
  EXPECT_TRUE(caps.joints[0].index);
  EXPECT_EQ(caps.joints[1].drive, JointDrive::Stepper);
  EXPECT_FALSE(caps.joints[1].index);
  EXPECT_EQ(caps.joints[0].switches, kSwitchLimitNeg | kSwitchLimitPos | kSwitchHome);
  EXPECT_EQ(caps.joints[2].switches, kSwitchLimitNeg | kSwitchLimitPos);
  EXPECT_TRUE(caps.spindle_encoder);
  EXPECT_TRUE(caps.probe);
  EXPECT_FALSE(caps.ups);
  EXPECT_EQ(caps.digital_inputs, 4);
}

TEST(SimMachine, SwitchesOnTheMachineDriveDigitalInputs) {
  SimMachineConfig c = machine_config();
  c.joints[2].drive = JointDrive::Manual;  // a hand-fed quill with a "tool up" switch at the top
  c.input_switches[0] = {2, 2, {true, -1.0, kInf}, 0.01, 0.0};
  SimMachine m(c);
  MachineInputs in;
  m.read(in);
  EXPECT_EQ(in.digital_in, 0b100u);  // the quill starts at 0, up
  m.set_hand_target(2, -30, 50);
  MachineOutputs out = holding();
  for (int k = 0; k < 1000; ++k) m.write(out);
  m.read(in);
  EXPECT_EQ(in.joints[2].position, -30.0);
  EXPECT_EQ(in.digital_in, 0u);
  m.set_digital_input(2, true);  // an injected value still reads
  m.write(out);
  m.read(in);
  EXPECT_EQ(in.digital_in, 0b100u);
}

TEST(SimMachine, HandwheelCountsAndTemperature) {
  SimMachineConfig c = machine_config();
  c.handwheel = true;
  c.temperature_c = 25;
  SimMachine m(c);
  EXPECT_TRUE(m.capabilities().handwheel);
  EXPECT_EQ(m.temperature_c(), 25.0);
  m.turn_handwheel(5);
  m.turn_handwheel(-7);
  MachineOutputs out = holding();
  m.write(out);
  MachineInputs in;
  m.read(in);
  EXPECT_EQ(in.handwheel_count, -2);
  c.handwheel = false;
  SimMachine none(c);
  none.turn_handwheel(5);
  none.write(out);
  none.read(in);
  EXPECT_EQ(in.handwheel_count, 0);
}

}  // namespace
}  // namespace opencnc::machine
