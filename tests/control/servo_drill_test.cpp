// SPDX-License-Identifier: GPL-3.0-or-later
// The drill retrofit's servo on its simulated machine (configs/drill-retrofit.toml): midpoint
// homing on the analog sensor (phases, edges, temperature), the compensation stage, the hand-fed
// quill, the handwheel, the interlock rules and a stall detector.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 60000)) << to_string(h.state());
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

/// Ticks until the machine is Idle, then a while longer for the take-up of the compensation.
void settle(ServoHarness& h) {
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 60000));
  h.tick(200);
}

TEST(MidpointHoming, GoesThroughTheSeedsStepsToTheMiddleOfTheSensor) {
  ServoHarness h(drill());
  on_in_manual(h);
  ASSERT_EQ(h.home(), Refusal::None);
  std::vector<HomingPhase> phases{HomingPhase::Idle};
  ASSERT_TRUE(h.until(
      [&] {
        const HomingPhase p = h.status().homing[kX].phase;
        if (p != phases.back()) phases.push_back(p);
        return h.state() == State::Idle;
      },
      60000));
  // Power-up at 0 is on the dog and the sensor: off them first, then the seed's sequence.
  const std::vector<HomingPhase> expected{HomingPhase::Idle,    HomingPhase::Clear,  HomingPhase::Search,
                                          HomingPhase::Overrun, HomingPhase::Return, HomingPhase::Measure,
                                          HomingPhase::Center,  HomingPhase::Final,  HomingPhase::Done};
  EXPECT_EQ(phases, expected);
  const HomingStatus& x = h.status().homing[kX];
  EXPECT_TRUE(x.measured);
  // The sensor switches on at level 0.5 (table −2.0) and off below 0.45, 25 µm past its zone's end
  // at +2.0: S = 4.025 mm, each edge within a micrometre (interpolated between periods).
  EXPECT_NEAR(x.rising_edge, -2.0, 0.001);
  EXPECT_NEAR(x.falling_edge, 2.025, 0.001);
  EXPECT_NEAR(x.width, 4.025, 0.001);
  EXPECT_EQ(x.origin_shift, 0.0);  // the first homing
  // Machine 0 is the middle of the two edges: table 0.0125 (± a step of 1.5625 µm).
  h.tick(300);
  EXPECT_EQ(h.status().commanded[Axis::X], 0.0);
  EXPECT_NEAR(h.sim().joint(kX).table_position(), 0.0125, 0.0016);
  EXPECT_NEAR(h.sim().joint(kY).table_position(), 0.0125, 0.0016);
}

// The sensing distance grows with temperature: both edges move outward, their middle stays. The
// single rising edge moves 2 µm/K; the origin found by the middle, not a micrometre.
TEST(MidpointHoming, MiddleStaysWhileTheEdgesDriftWithTemperature) {
  std::vector<double> middle, rising;
  const double temperatures[] = {12.0, 20.0, 28.0, 36.0};
  const char* starts[] = {"0.0", "150.0", "37.5", "420.0"};
  for (int run = 0; run < 4; ++run) {
    ServoHarness h(drill(
        {"sim.seed=" + std::to_string(31 + run), std::string("axis.x.sim.start_position=") + starts[run]}));
    h.sim().set_temperature(temperatures[run]);
    home_all(h);
    const HomingStatus& x = h.status().homing[kX];
    middle.push_back(0.5 * (x.rising_edge + x.falling_edge));
    rising.push_back(x.rising_edge);
    EXPECT_NEAR(x.rising_edge, -2.0 - 0.002 * (temperatures[run] - 20), 0.001) << temperatures[run];
  }
  const auto spread = [](const std::vector<double>& v) {
    return *std::max_element(v.begin(), v.end()) - *std::min_element(v.begin(), v.end());
  };
  EXPECT_LE(spread(middle), 0.001);
  EXPECT_NEAR(spread(rising), 0.048, 0.002);
}

TEST(MidpointHoming, FaultsWhenTheSensorIsNotOnTheDog) {
  // A dog that ends at table 1 mm, inside the sensor's zone: the falling edge comes after it.
  ServoHarness h(drill({"axis.x.switches.decel=[-inf, 1.0]", "axis.x.sim.start_position=100.0"}));
  on_in_manual(h);
  ASSERT_EQ(h.home(kX), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Faulted; }, 60000));
  EXPECT_EQ(h.status().fault.kind, FaultKind::Homing);
  EXPECT_EQ(h.status().fault.axis, kX);
  EXPECT_FALSE(h.status().joints[kX].homed);
}

// At 175 mm the seed's table asks for 0.0125 mm; with it and the backlash corrected the table
// stands where the program says, coming from either side.
TEST(CompensationStage, PutsTheTableWhereItWasCommanded) {
  ServoHarness h(drill());
  home_all(h);
  h.tick(300);
  const double origin = h.sim().joint(kX).table_position();  // machine 0 on the table
  ASSERT_EQ(jog_by(h, Axis::X, 175.0, 40.0), Refusal::None);
  settle(h);
  EXPECT_EQ(h.status().commanded[Axis::X], 175.0);
  // −E(175) for the pitch, +B/2 for the backlash of a motion in +.
  EXPECT_NEAR(h.status().compensation[kX], -0.0125 + 0.01, 1e-12);
  EXPECT_NEAR(h.sim().joint(kX).table_position() - origin, 175.0, 0.0016);
  ASSERT_EQ(jog_by(h, Axis::X, 100.0, 40.0), Refusal::None);  // past it, and back from above
  settle(h);
  ASSERT_EQ(jog_by(h, Axis::X, -100.0, 40.0), Refusal::None);
  settle(h);
  EXPECT_NEAR(h.status().compensation[kX], -0.0125 - 0.01, 1e-12);
  EXPECT_NEAR(h.sim().joint(kX).table_position() - origin, 175.0, 0.0016);
}

TEST(CompensationStage, WithoutItTheScrewErrorAndTheBacklashShow) {
  ServoHarness h(drill({"axis.x.compensation.errors=[0.0]", "axis.x.compensation.backlash=0"}));
  home_all(h);
  h.tick(300);
  const double origin = h.sim().joint(kX).table_position();
  ASSERT_EQ(jog_by(h, Axis::X, 175.0, 40.0), Refusal::None);
  settle(h);
  EXPECT_EQ(h.status().compensation[kX], 0.0);
  // 12.5 µm of screw error and the 20 µm of backlash the homing's last move (in −) left taken up
  // the other way.
  EXPECT_NEAR(h.sim().joint(kX).table_position() - origin, 175.0 + 0.0125 - 0.02, 0.0016);
}

TEST(HandAxis, FollowsTheOperatorAndIsNeverCommanded) {
  ServoHarness h(drill());
  on_in_manual(h);
  EXPECT_TRUE(h.status().joints[kZ].homed);  // at its top stop at power-up
  h.sim().set_hand_target(kZ, -30.0, 20.0);
  h.tick(3000);
  EXPECT_EQ(h.status().joints[kZ].actual, -30.0);
  EXPECT_EQ(h.status().commanded[Axis::Z], -30.0);
  EXPECT_EQ(h.status().joints[kZ].following_error, 0.0);
  EXPECT_EQ(h.jog(Axis::Z, 5.0), Refusal::HandAxis);
  EXPECT_EQ(h.home(kZ), Refusal::HandAxis);
  // Homing every axis leaves the quill alone.
  ASSERT_EQ(h.home(), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 60000));
  EXPECT_EQ(h.status().joints[kZ].actual, -30.0);
}

TEST(Handwheel, MovesTheSelectedAxisByTheSelectedStep) {
  ServoHarness h(drill());
  home_all(h);
  Command sel;
  sel.kind = CommandKind::SetHandwheel;
  sel.axis = static_cast<std::int8_t>(index(Axis::X));
  sel.value = 0.005;
  EXPECT_EQ(h.send(sel), Refusal::BadValue);  // not one of the profile's steps
  sel.value = 0.01;
  ASSERT_EQ(h.send(sel), Refusal::None);
  EXPECT_EQ(h.status().handwheel_axis, kX);
  h.sim().turn_handwheel(25);
  h.tick(5);
  h.sim().turn_handwheel(-5);
  h.tick(2);  // the counts reach the servo with the next sample
  settle(h);
  EXPECT_DOUBLE_EQ(h.status().commanded[Axis::X], 0.2);
  // At the soft limit (−5) it stops: 1000 counts down go 5.2 mm at most.
  h.sim().turn_handwheel(-1000);
  h.tick(2);
  settle(h);
  EXPECT_EQ(h.status().commanded[Axis::X], -5.0);
  sel.axis = static_cast<std::int8_t>(index(Axis::Z));
  EXPECT_EQ(h.send(sel), Refusal::HandAxis);
  sel.axis = -1;
  ASSERT_EQ(h.send(sel), Refusal::None);
  h.sim().turn_handwheel(100);
  h.tick(500);
  EXPECT_EQ(h.status().commanded[Axis::X], -5.0);
}

Refusal spindle_on(ServoHarness& h) {
  Command c;
  c.kind = CommandKind::SpindleOn;
  c.value = 600;
  c.flag = true;
  return h.send(c);
}

// "stop spindle when tool_up" and "block spindle unless tool_up and table_still and not door_open".
TEST(Interlocks, SpindleStartsWithTheToolUpAndStopsWhenItComesBackUp) {
  ServoHarness h(drill());
  on_in_manual(h);
  ASSERT_EQ(spindle_on(h), Refusal::None);
  h.tick(100);
  EXPECT_EQ(h.status().spindle_direction, machine::SpindleDirection::Clockwise);
  h.sim().set_hand_target(kZ, -20.0, 30.0);  // the operator drills
  h.tick(2000);
  EXPECT_EQ(h.status().spindle_direction, machine::SpindleDirection::Clockwise);  // a running one runs on
  h.sim().set_hand_target(kZ, 0.0, 30.0);                                         // and comes back to the top
  h.tick(2000);
  EXPECT_EQ(h.status().spindle_direction, machine::SpindleDirection::Stopped);
  const auto e = h.last(EventKind::Interlock);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->action, 0u);  // the first rule
  EXPECT_EQ(e->command, CommandKind::SpindleOff);
  h.sim().set_hand_target(kZ, -5.0, 30.0);
  h.tick(1000);
  EXPECT_EQ(spindle_on(h), Refusal::Interlock);  // the tool is not up
  EXPECT_EQ(h.status().interlock_rule, 2);
  h.sim().set_hand_target(kZ, 0.0, 30.0);
  h.tick(1000);
  EXPECT_EQ(spindle_on(h), Refusal::None);
}

TEST(Interlocks, TheDoorHoldsMotionAndTheLampShowsReady) {
  ServoHarness h(drill());
  on_in_manual(h);
  h.tick(2);
  EXPECT_EQ(h.status().digital_out & 1u, 0u);  // "set ready_lamp when machine_on and x_homed and y_homed"
  ASSERT_EQ(h.home(), Refusal::None);
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 60000));
  h.tick(2);
  EXPECT_EQ(h.status().digital_out & 1u, 1u);
  ASSERT_EQ(h.jog(Axis::Y, 20.0), Refusal::None);
  h.tick(200);
  h.sim().set_digital_input(1, true);  // the guard opens: "hold motion when door_open"
  ASSERT_TRUE(h.until([&] { return h.state() == State::Idle; }, 2000));
  const auto e = h.last(EventKind::Interlock);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->command, CommandKind::JogStop);
  EXPECT_EQ(spindle_on(h), Refusal::Interlock);
  h.sim().set_digital_input(1, false);
  h.tick(2);
  EXPECT_EQ(spindle_on(h), Refusal::None);
  ASSERT_EQ(h.send(CommandKind::MachineOff), Refusal::None);
  h.tick(2);
  EXPECT_EQ(h.status().digital_out & 1u, 0u);
}

// "block motion when door_open" refuses every start but lets what moves go on; "estop when
// stop_button" e-stops and refuses reset while it holds.
TEST(Interlocks, BlockedMotionAndAnEStopRule) {
  ServoHarness h(drill({"interlocks.inputs.stop_button=2",
                        "interlocks.rules=[\"block motion when door_open\", \"estop when stop_button\"]"}));
  home_all(h);
  ASSERT_EQ(h.jog(Axis::Y, 20.0), Refusal::None);
  h.tick(100);
  h.sim().set_digital_input(1, true);  // the guard opens while Y moves
  h.tick(100);
  EXPECT_EQ(h.state(), State::Running);  // a block holds back starts, not what already moves
  EXPECT_GT(h.status().joints[kY].velocity, 19.0);
  ASSERT_EQ(h.send(Command{0, CommandKind::JogStop}), Refusal::None);
  settle(h);
  EXPECT_EQ(h.jog(Axis::X, 10.0), Refusal::Interlock);
  EXPECT_EQ(h.home(), Refusal::Interlock);
  EXPECT_EQ(h.send_mode(Mode::Auto), Refusal::None);
  Command run;
  run.kind = CommandKind::StartRun;
  run.run_mode = Mode::Auto;
  EXPECT_EQ(h.send(run), Refusal::Interlock);
  EXPECT_EQ(h.send_mode(Mode::Manual), Refusal::None);
  h.sim().set_digital_input(1, false);
  h.tick(2);
  EXPECT_EQ(h.jog(Axis::X, 10.0), Refusal::None);
  h.tick(50);
  h.sim().set_digital_input(2, true);  // "estop when stop_button"
  h.tick(2);
  EXPECT_EQ(h.state(), State::EStopped);
  EXPECT_FALSE(h.status().drives_enabled);
  const auto e = h.last(EventKind::Interlock);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->action, 1u);
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::Interlock);
  h.sim().set_digital_input(2, false);
  h.tick(2);
  EXPECT_EQ(h.send(CommandKind::Reset), Refusal::None);
  EXPECT_EQ(h.state(), State::Off);
}

TEST(Stall, ADetectedStallFaultsAndTheAxisMustHomeAgain) {
  ServoHarness h(drill());
  home_all(h);
  ASSERT_EQ(h.jog(Axis::X, 30.0), Refusal::None);
  h.tick(300);
  h.sim().set_external_effort(kX, -3000.0);  // the table runs into something
  ASSERT_TRUE(h.until([&] { return h.state() == State::Faulted; }, 1000));
  EXPECT_EQ(h.status().fault.kind, FaultKind::Stall);
  EXPECT_EQ(h.status().fault.axis, kX);
  EXPECT_FALSE(h.status().joints[kX].homed);
  EXPECT_FALSE(h.status().drives_enabled);
}

TEST(Stall, WithoutADetectorStepsAreLostSilently) {
  ServoHarness h(drill());
  home_all(h);
  ASSERT_EQ(h.jog(Axis::Y, 30.0), Refusal::None);
  h.tick(300);
  h.sim().set_external_effort(kY, -1300.0);  // beyond what the motor gives at 30 mm/s, briefly
  h.tick(20);
  h.sim().set_external_effort(kY, 0.0);
  ASSERT_EQ(h.send(Command{0, CommandKind::JogStop}), Refusal::None);
  settle(h);
  EXPECT_NE(h.state(), State::Faulted);
  EXPECT_TRUE(h.status().joints[kY].homed);
  EXPECT_GT(h.sim().joint(kY).lost_steps(), 100);
}

}  // namespace
}  // namespace opencnc::control::test
