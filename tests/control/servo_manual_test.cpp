// SPDX-License-Identifier: GPL-3.0-or-later
// Manual mode on the simulated machine: homing in sequences on noisy switches (repeatable to the
// micrometre), jogs that stop exactly at the soft limits, jogging off a limit switch; the EDM's
// homing on its reference cams and seeks of its limit switches.
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

// --- the five-axis EDM: homing on its cams, seeking its limit switches ------------------------

constexpr int kC = 4;

config::MachineProfile edm(std::vector<std::string> sets = {}) {
  return loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml", sets));
}

Refusal seek(ServoHarness& h, Axis a, int direction) {
  Command c;
  c.kind = CommandKind::SeekLimit;
  c.axis = static_cast<std::int8_t>(index(a));
  c.value = direction;
  return h.send(c);
}

std::vector<ServoEvent> seek_events(ServoHarness& h) {
  std::vector<ServoEvent> v;
  for (const ServoEvent& e : h.events()) {
    if (e.kind == EventKind::LimitSeek) v.push_back(e);
  }
  return v;
}

// Steppers know nothing at power-up: every axis searches its cam's edge (from on the cam it moves
// off first), backs off and latches it at 0.2 mm/s. Other switch noise and power-up positions on
// either side of the edges give the same home reference to within a step (0.625 µm) and the
// switch's noise; C finds its mark, which comes round every turn.
TEST(EdmHoming, LandsOnTheCamsWithinTheLatchsRepeatability) {
  std::array<std::vector<double>, 5> refs;
  const char* starts[] = {"-2.5", "1.5", "-0.7", "3.2"};
  for (int run = 0; run < 4; ++run) {
    const std::string p = starts[run];
    std::vector<std::string> sets = {"sim.seed=" + std::to_string(run + 3)};
    for (const char* a : {"x", "y", "z", "b"})
      sets.push_back(std::string("axis.") + a + ".sim.start_position=" + p);
    sets.push_back("axis.c.sim.start_position=" + std::string(run % 2 ? "358.5" : "1.0"));
    ServoHarness h(edm(sets));
    EXPECT_FALSE(h.status().all_homed);
    home_all(h);
    h.tick(50);
    for (int j = 0; j < 5; ++j) {
      const double ref =
          h.status().joints[static_cast<std::size_t>(j)].actual - h.sim().joint(j).table_position();
      refs[static_cast<std::size_t>(j)].push_back(j == kC ? std::remainder(ref, 360.0) : ref);
      EXPECT_NEAR(h.status().commanded[static_cast<Axis>(j)], 0.0, 1e-9);
    }
  }
  for (int j = 0; j < 5; ++j) {
    const auto& v = refs[static_cast<std::size_t>(j)];
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    std::printf("EDM home reference of joint %d: %.3g spread\n", j, *hi - *lo);
    EXPECT_LE(*hi - *lo, 0.001) << "joint " << j;         // a step (0.625 µm) and the noise
    EXPECT_NEAR(v.front(), 0.0, 0.003) << "joint " << j;  // the cams' edges are at table 0
  }
}

// Not homed: the seek runs at 20 mm/s until X's + switch (table 151) trips, stops within the 4 mm
// overtravel, comes off it and onto it again at 0.5 mm/s, and rests 0.5 mm on the free side of
// where it released. No fault: that trip is what it sought.
TEST(LimitSeek, StopsAtTheSwitchAndBacksOffOntoItsFreeSide) {
  ServoHarness h(edm({"axis.x.sim.start_position=147.0"}));
  on_in_manual(h);
  ASSERT_EQ(seek(h, Axis::X, +1), Refusal::None);
  EXPECT_EQ(h.state(), State::Running);
  double furthest = 0;
  bool shown = false;
  ASSERT_TRUE(h.until(
      [&] {
        furthest = std::max(furthest, h.sim().joint(kX).table_position());
        shown = shown || h.status().seek[kX].phase == SeekPhase::Latch;
        return h.state() != State::Running;
      },
      20000));
  EXPECT_EQ(h.state(), State::Idle);
  EXPECT_TRUE(shown);
  EXPECT_GT(furthest, 151.0);
  EXPECT_LT(furthest, 151.0 + 4.0);
  const std::vector<ServoEvent> found = seek_events(h);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].action, 1u);
  EXPECT_NEAR(found[0].value, 151.0, 0.002);  // machine = table before homing
  const LimitSeekStatus& st = h.status().seek[kX];
  EXPECT_EQ(st.phase, SeekPhase::Done);
  EXPECT_TRUE(st.found);
  EXPECT_NEAR(st.tripped_at, 151.0, 0.002);
  EXPECT_NEAR(st.rest_at, st.released_at - 0.5, 1e-9);
  EXPECT_NEAR(st.released_at, 151.0 - 0.01, 0.003);  // the switch's differential travel
  h.tick(100);
  EXPECT_FALSE(h.status().joints[kX].limit_pos);
  EXPECT_NEAR(h.sim().joint(kX).table_position(), st.rest_at, 0.001);
}

// Homed, the seek goes past the soft limit (no fault) to the switch and comes to rest back on the
// soft limit, so that the axis can jog and run programs at once.
TEST(LimitSeek, AHomedAxisComesBackWithinItsSoftLimits) {
  ServoHarness h(edm());
  home_all(h);
  ASSERT_EQ(seek(h, Axis::Z, -1), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() != State::Running; }, 20000));
  ASSERT_EQ(h.state(), State::Idle) << fault_code(h.status().fault.kind);
  const LimitSeekStatus& st = h.status().seek[kZ];
  EXPECT_TRUE(st.found);
  EXPECT_NEAR(st.tripped_at, -81.0, 0.003);
  EXPECT_DOUBLE_EQ(st.rest_at, -80.0);
  EXPECT_DOUBLE_EQ(h.status().commanded[Axis::Z], -80.0);
  EXPECT_TRUE(h.status().all_homed);
}

// A switch that does not trip: the homed search ends at the soft limit + overtravel, faults, and
// the axis must home again.
TEST(LimitSeek, ASwitchThatNeverTripsIsAFault) {
  ServoHarness h(edm({"axis.y.switches.limit_max=130.0"}));  // the switch moved beyond the stops
  home_all(h);
  ASSERT_EQ(seek(h, Axis::Y, +1), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() != State::Running; }, 20000))
      << to_string(h.status().seek[kY].phase) << " " << h.status().commanded[Axis::Y];
  EXPECT_EQ(h.state(), State::Faulted);
  EXPECT_EQ(h.status().fault.kind, FaultKind::SeekNoSwitch);
  EXPECT_NEAR(h.status().fault.value, 104.0, 1e-6);
  EXPECT_FALSE(h.status().joints[kY].homed);
  const std::vector<ServoEvent> ev = seek_events(h);
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].action, 0u);
}

TEST(LimitSeek, IsRefusedWithoutASwitchOutsideManualOrWhileSomethingMoves) {
  ServoHarness h(edm({"axis.x.sim.start_position=140.0"}));
  EXPECT_EQ(seek(h, Axis::X, +1), Refusal::MachineOff);
  on_in_manual(h);
  EXPECT_EQ(seek(h, Axis::C, +1), Refusal::NoLimitSwitch);  // C turns without end: no limit switch
  EXPECT_EQ(seek(h, Axis::X, 0), Refusal::BadValue);
  ASSERT_EQ(h.send_mode(Mode::Mdi), Refusal::None);
  EXPECT_EQ(seek(h, Axis::X, +1), Refusal::WrongMode);
  ASSERT_EQ(h.send_mode(Mode::Manual), Refusal::None);
  ASSERT_EQ(h.jog(Axis::Y, 5), Refusal::None);
  EXPECT_EQ(seek(h, Axis::X, +1), Refusal::Busy);
  ASSERT_EQ(h.send(Command{0, CommandKind::JogStop}), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 2000));
  ASSERT_EQ(seek(h, Axis::X, +1), Refusal::None);
  EXPECT_EQ(h.jog(Axis::Y, 5), Refusal::Busy);  // nothing else moves beside a seek
  EXPECT_TRUE(seek_events(h).empty());
}

// E-stop during the search: the seek ends where it is, the axis never reaches the switch, and
// nothing is reported as found. A jog stop ends a seek too.
TEST(LimitSeek, EStopOrJogStopDuringASeekStopsIt) {
  ServoHarness h(edm({"axis.x.sim.start_position=140.0"}));
  on_in_manual(h);
  ASSERT_EQ(seek(h, Axis::X, +1), Refusal::None);
  h.tick(200);
  ASSERT_EQ(h.status().seek[kX].phase, SeekPhase::Search);
  ASSERT_EQ(h.send(CommandKind::EStop), Refusal::None);
  EXPECT_EQ(h.state(), State::EStopped);
  EXPECT_EQ(h.status().seek[kX].phase, SeekPhase::Idle);
  h.tick(2000);  // the drives are off: the table coasts to rest on its friction
  const double stopped = h.sim().joint(kX).table_position();
  EXPECT_LT(stopped, 145.0);  // 4 mm after the seek began, 6 mm short of the switch
  h.tick(1000);
  EXPECT_EQ(h.sim().joint(kX).table_position(), stopped);
  EXPECT_TRUE(seek_events(h).empty());

  ASSERT_EQ(h.send(CommandKind::Reset), Refusal::None);
  on_in_manual(h);
  ASSERT_EQ(seek(h, Axis::X, +1), Refusal::None);
  h.tick(100);
  ASSERT_EQ(h.send(Command{0, CommandKind::JogStop}), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 2000));
  EXPECT_EQ(h.status().seek[kX].phase, SeekPhase::Idle);
  EXPECT_FALSE(h.status().joints[kX].limit_pos);
  EXPECT_TRUE(seek_events(h).empty());
}

}  // namespace
}  // namespace opencnc::control::test
