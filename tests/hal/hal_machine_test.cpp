// SPDX-License-Identifier: GPL-3.0-or-later
// HalMachine over plain variables standing in for HAL pins: what the servo reads and writes, the
// capabilities clipped to the pins, and the feedback kept continuous across an index mark.
#include <gtest/gtest.h>

#include "opencnc/hal/hal_machine.hpp"

namespace opencnc::hal::test {
namespace {

/// Storage for every pin (HAL would put it in its shared memory).
struct FakePins {
  struct Joint {
    double pos_cmd = 0, vel_cmd = 0, pos_fb = 0, effort = 0;
    std::int32_t step_cmd = 0;
    bool enable = false, amp_fault = false, home_sw = false, limit_min = false, limit_max = false,
         index = false;
  };
  std::array<Joint, 2> joints{};
  bool estop_in = true, estop_out = false, power_fail = false, probe = false, bits[16] = {};
  double floats[8] = {};
  std::int32_t s32[2] = {};
  std::array<bool, 4> din{}, dout{};
  MachinePins pins;

  FakePins() {
    for (std::size_t j = 0; j < joints.size(); ++j) {
      Joint& s = joints[j];
      JointPins& p = pins.joints[j];
      p = {&s.pos_cmd, &s.vel_cmd,   &s.step_cmd,  &s.pos_fb, &s.enable, &s.amp_fault,
           &s.home_sw, &s.limit_min, &s.limit_max, &s.index,  &s.effort};
    }
    pins.estop_in = &estop_in;
    pins.estop_out = &estop_out;
    pins.power_fail = &power_fail;
    pins.probe_in = &probe;
    pins.spindle_speed_out = &floats[0];
    pins.spindle_orient_angle = &floats[1];
    pins.spindle_speed_in = &floats[2];
    pins.spindle_revs = &floats[3];
    pins.spindle_torque = &floats[4];
    Bit** bit_pins[] = {&pins.spindle_on,
                        &pins.spindle_forward,
                        &pins.spindle_reverse,
                        &pins.spindle_orient,
                        &pins.spindle_at_speed,
                        &pins.spindle_orient_done,
                        &pins.spindle_fault,
                        &pins.flood,
                        &pins.mist,
                        &pins.tool_prepare,
                        &pins.tool_change,
                        &pins.tool_prepared,
                        &pins.tool_changed};
    for (std::size_t i = 0; i < std::size(bit_pins); ++i) *bit_pins[i] = &bits[i];
    pins.tool_prepare_number = &s32[0];
    pins.handwheel_counts = &s32[1];
    for (std::size_t i = 0; i < din.size(); ++i) {
      pins.digital_in[i] = &din[i];
      pins.digital_out[i] = &dout[i];
    }
    pins.joint_count = 2;
    pins.digital_inputs = pins.digital_outputs = 4;
  }
};

machine::MachineCapabilities caps() {
  machine::MachineCapabilities c;
  c.joint_count = 3;  // more than the pins: clipped to 2
  c.joints[0].switches = machine::kSwitchLimitNeg | machine::kSwitchLimitPos | machine::kSwitchHome;
  c.joints[0].index = true;
  c.spindle = true;
  c.digital_inputs = 8;
  c.digital_outputs = 2;
  return c;
}

// The drives' efforts are read only where the component was told they are netted: an unconnected
// float pin reads 0, which would show as a load of 0 %.
TEST(HalMachine, ReadsTheEffortsOnlyWhereTheyAreWired) {
  machine::MachineCapabilities c = caps();
  c.joints[0].effort = true;  // a servo drive
  c.spindle_torque = true;
  for (bool wired : {false, true}) {
    FakePins f;
    f.pins.effort_wired = wired;
    HalMachine m(f.pins);
    m.set_capabilities(c);
    EXPECT_EQ(m.capabilities().joints[0].effort, wired);
    EXPECT_FALSE(m.capabilities().joints[1].effort);  // the profile's joint 1 reports none
    EXPECT_EQ(m.capabilities().spindle_torque, wired);
    f.joints[0].effort = -412.5;
    f.joints[1].effort = 99;
    f.floats[4] = 7.25;
    machine::MachineInputs in;
    m.read(in);
    EXPECT_DOUBLE_EQ(in.joints[0].effort, wired ? -412.5 : 0.0);
    EXPECT_DOUBLE_EQ(in.joints[1].effort, 0.0);
    EXPECT_DOUBLE_EQ(in.spindle.torque_nm, wired ? 7.25 : 0.0);
  }
}

TEST(HalMachine, ReadsAndWritesThePins) {
  FakePins f;
  HalMachine m(f.pins);
  m.set_capabilities(caps());
  EXPECT_EQ(m.capabilities().joint_count, 2);
  EXPECT_EQ(m.capabilities().digital_inputs, 4);
  EXPECT_TRUE(m.capabilities().power_monitor);

  f.joints[0].pos_fb = 1.25;
  f.joints[0].limit_max = true;
  f.joints[1].limit_max = true;  // joint 1 declares no switches: ignored
  f.joints[1].amp_fault = true;
  f.din[2] = true;
  f.power_fail = true;
  f.bits[4] = true;  // spindle at speed
  machine::MachineInputs in;
  m.read(in);
  EXPECT_DOUBLE_EQ(in.joints[0].position, 1.25);
  EXPECT_TRUE(in.joints[0].limit_pos);
  EXPECT_FALSE(in.joints[1].limit_pos);
  EXPECT_TRUE(in.joints[1].amp_fault);
  EXPECT_TRUE(in.estop_ok);
  EXPECT_FALSE(in.power.mains_ok);
  EXPECT_TRUE(in.spindle.at_speed);
  EXPECT_EQ(in.digital_in, 0b100u);

  machine::MachineOutputs out;
  out.joints[0] = {2.5, 10.0, 12345, true};
  out.estop_release = true;
  out.spindle.speed_rpm = 1200;
  out.spindle.direction = machine::SpindleDirection::Counterclockwise;
  out.digital_out = 0b11;
  m.write(out);
  EXPECT_DOUBLE_EQ(f.joints[0].pos_cmd, 2.5);
  EXPECT_DOUBLE_EQ(f.joints[0].vel_cmd, 10.0);
  EXPECT_EQ(f.joints[0].step_cmd, 12345);
  EXPECT_TRUE(f.joints[0].enable);
  EXPECT_TRUE(f.estop_out);
  EXPECT_DOUBLE_EQ(f.floats[0], -1200.0);
  EXPECT_TRUE(f.bits[0] && !f.bits[1] && f.bits[2]);  // on, not forward, reverse
  EXPECT_TRUE(f.dout[0] && f.dout[1] && !f.dout[2]);  // two outputs declared
  EXPECT_TRUE(f.joints[0].index);                     // armed: the joint has an index
  EXPECT_FALSE(f.joints[1].index);
}

// The encoder zeroes its count at the mark and clears index-enable: the servo sees one index count,
// the mark where it was, and feedback without a jump; the commands go out in the encoder's frame.
TEST(HalMachine, AnIndexMarkKeepsTheFeedbackContinuous) {
  FakePins f;
  HalMachine m(f.pins);
  m.set_capabilities(caps());
  m.set_period_ns(1'000'000);
  machine::MachineInputs in;
  machine::MachineOutputs out;
  out.joints[0].enable = true;
  for (int i = 0; i <= 10; ++i) {  // 5 mm/s: 0.005 mm per period
    f.joints[0].pos_fb = 0.005 * i;
    m.read(in);
    m.write(out);
  }
  ASSERT_TRUE(f.joints[0].index);
  f.joints[0].index = false;   // the mark at 0.052: the count restarts there
  f.joints[0].pos_fb = 0.003;  // 0.055 − 0.052
  m.read(in);
  EXPECT_EQ(in.joints[0].index_count, 1u);
  EXPECT_NEAR(in.joints[0].index_position, 0.052, 1e-12);
  EXPECT_NEAR(in.joints[0].position, 0.055, 1e-12);
  out.joints[0].position = 0.06;
  m.write(out);
  EXPECT_NEAR(f.joints[0].pos_cmd, 0.008, 1e-12);
}

}  // namespace
}  // namespace opencnc::hal::test
