// SPDX-License-Identifier: GPL-3.0-or-later
// Manual mode on the simulated machine: homing in sequences on noisy switches (repeatable to the
// micrometre), jogs that stop exactly at the soft limits, jogging off a limit switch.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "servo_harness.hpp"
#include "test_profiles.hpp"

namespace opencnc::control::test {
namespace {

constexpr int kX = 0, kY = 1, kZ = 2;

void on_in_manual(ServoHarness& h) {
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  ASSERT_EQ(h.send_mode(Mode::Manual), Refusal::None);
}

void home_all(ServoHarness& h) {
  on_in_manual(h);
  ASSERT_EQ(h.home(), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 120000)) << to_string(h.state());
  ASSERT_TRUE(h.status().all_homed);
}

Refusal jog_by(ServoHarness& h, Axis a, double distance, double speed) {
  Command c;
  c.kind = CommandKind::JogIncrement;
  c.axis = static_cast<std::int8_t>(index(a));
  c.value = distance;
  c.value2 = speed;
  return h.send(c);
}

TEST(Homing, HomesEveryJointInItsSequence) {
  ServoHarness h(homing_mill());
  EXPECT_FALSE(h.status().all_homed);
  home_all(h);
  const ServoStatus& s = h.status();
  EXPECT_DOUBLE_EQ(s.commanded[Axis::X], 290.0);
  EXPECT_DOUBLE_EQ(s.commanded[Axis::Y], 5.0);
  EXPECT_DOUBLE_EQ(s.commanded[Axis::Z], -5.0);
  // Z (sequence 0) before X and Y (sequence 1).
  std::vector<int> order;
  for (const ServoEvent& e : h.events()) {
    if (e.kind == EventKind::Homed) order.push_back(e.axis);
  }
  ASSERT_EQ(order.size(), 3u);
  EXPECT_EQ(order[0], kZ);
  // Each latch put the switch edge or index mark at the profile's switch position: machine
  // position − table position (the home reference) follows from where the switches are.
  // X latched the rising edge of the switch at table 100 (± noise, hysteresis on the way back).
  EXPECT_NEAR(s.joints[kX].actual - h.sim().joint(kX).table_position(), 200.0, 0.002);
  // Y latched the index mark after the switch released on the way back: marks at 0.3 + 5k, the
  // switch ends at −50, so the mark at −49.7 is machine 0.
  EXPECT_NEAR(s.joints[kY].actual - h.sim().joint(kY).table_position(), 49.7, 1e-4);
  // Z slowed on the dog at 40 and latched the home switch at 45.
  EXPECT_NEAR(s.joints[kZ].actual - h.sim().joint(kZ).table_position(), -45.0, 0.002);
}

// The home reference (machine position − table position) of every axis, from homing runs with
// other switch noise and other power-up positions, agrees to the micrometre; with the index mark
// to the encoder count.
TEST(Homing, IsRepeatableToTheMicrometre) {
  std::array<std::vector<double>, 3> offsets;
  const char* starts[] = {"0.0", "20.0", "-30.0", "55.5", "80.0"};
  for (int run = 0; run < 5; ++run) {
    const std::string s = starts[run];
    ServoHarness h(homing_mill({"sim.seed=" + std::to_string(run + 11), "axis.x.sim.start_position=" + s,
                                "axis.y.sim.start_position=" + s, "axis.z.sim.start_position=" + s}));
    home_all(h);
    h.tick(200);
    for (int j : {kX, kY, kZ}) {
      offsets[static_cast<std::size_t>(j)].push_back(h.status().joints[static_cast<std::size_t>(j)].actual -
                                                     h.sim().joint(j).table_position());
    }
  }
  const auto worst = [](const std::vector<double>& v) {  // largest distance from the mean
    double mean = 0, w = 0;
    for (double x : v) mean += x / static_cast<double>(v.size());
    for (double x : v) w = std::max(w, std::fabs(x - mean));
    return w;
  };
  std::printf("home reference spread from the mean: X %.3g Y %.3g Z %.3g mm\n", worst(offsets[kX]),
              worst(offsets[kY]), worst(offsets[kZ]));
  EXPECT_LE(worst(offsets[kX]), 1e-3);
  EXPECT_LE(worst(offsets[kY]), 1.0 / 13107.2);  // the index mark: within an encoder count
  EXPECT_LE(worst(offsets[kZ]), 1e-3);
}

TEST(Homing, AutoAndMdiNeedIt) {
  ServoHarness h(homing_mill());
  on_in_manual(h);
  ASSERT_EQ(h.send_mode(Mode::Auto), Refusal::None);
  Command c;
  c.kind = CommandKind::StartRun;
  c.run_mode = Mode::Auto;
  EXPECT_EQ(h.send(c), Refusal::NotHomed);
}

TEST(Jog, ContinuousJogStopsExactlyAtTheSoftLimit) {
  ServoHarness h(homing_mill());
  home_all(h);
  ASSERT_EQ(h.jog(Axis::X, 50), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 5000));
  EXPECT_EQ(h.status().commanded[Axis::X], 300.0);
  h.tick(500);
  EXPECT_NEAR(h.status().joints[kX].actual, 300.0, 0.002);
  // At the limit a jog toward it goes nowhere; away from it, it moves.
  ASSERT_EQ(h.jog(Axis::X, 50), Refusal::None);
  h.tick(100);
  EXPECT_EQ(h.status().commanded[Axis::X], 300.0);
  ASSERT_EQ(h.jog(Axis::X, -50), Refusal::None);
  h.tick(100);
  EXPECT_LT(h.status().commanded[Axis::X], 299.0);
  ASSERT_EQ(h.send(Command{0, CommandKind::JogStop}), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 5000));
}

TEST(Jog, IncrementsAreExactAndClampedToTheSoftLimit) {
  ServoHarness h(homing_mill());
  home_all(h);
  ASSERT_EQ(jog_by(h, Axis::Y, 0.001, 10), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 1000));
  EXPECT_DOUBLE_EQ(h.status().commanded[Axis::Y], 5.001);
  ASSERT_EQ(jog_by(h, Axis::Y, -100, 80), Refusal::None);  // would reach −95, the limit is −10
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 5000));
  EXPECT_EQ(h.status().commanded[Axis::Y], -10.0);
}

TEST(Jog, UnhomedJogIntoALimitSwitchFaultsAndCanJogOffAfterReset) {
  ServoHarness h(homing_mill());
  on_in_manual(h);
  ASSERT_EQ(h.jog(Axis::X, 50), Refusal::None);  // no soft limits before homing
  ASSERT_TRUE(h.until([&] { return h.state() == State::Faulted; }, 10000));
  const Fault f = h.status().fault;
  EXPECT_EQ(f.kind, FaultKind::LimitSwitch);
  EXPECT_EQ(f.axis, kX);
  EXPECT_NEAR(f.value, 160.0, 0.1);  // the switch at table 160, machine = table before homing
  EXPECT_FALSE(h.status().drives_enabled);
  ASSERT_EQ(h.send(CommandKind::Reset), Refusal::None);
  ASSERT_EQ(h.send(CommandKind::MachineOn), Refusal::None);
  EXPECT_TRUE(h.status().joints[kX].limit_pos);
  EXPECT_EQ(h.jog(Axis::X, 10), Refusal::LimitSwitch);
  ASSERT_EQ(h.jog(Axis::X, -10), Refusal::None);
  ASSERT_TRUE(h.until([&] { return !h.status().joints[kX].limit_pos; }, 5000));
  EXPECT_EQ(h.state(), State::Running);
}

}  // namespace
}  // namespace opencnc::control::test
