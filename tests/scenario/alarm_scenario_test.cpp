// SPDX-License-Identifier: GPL-3.0-or-later
// Process-input alarms through the whole controller on the simulated EDM test machine: the resistor
// box's temperature rising past its bound warns and nothing stops; the dielectric's temperature
// holds the program until it is back inside by the hysteresis; the dielectric's level sinking
// stops the machine with a fault that reset cannot clear while the level is low.
#include <gtest/gtest.h>

#include <string>

#include "opencnc/config/profile_loader.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

config::MachineProfile edm_profile() {
  const config::ProfileLoad load =
      config::load_profile(OPENCNC_SOURCE_DIR "/tests/scenario/edm-setting.toml");
  for (const Diagnostic& d : load.diagnostics.items()) ADD_FAILURE() << d.format();
  EXPECT_TRUE(load.profile.has_value());
  return *load.profile;
}

constexpr const char* kCut = "G21 G90\nG1 X20 F600\nG1 Y20\nM2\n";  // 4 s of feed

constexpr int kLevel = 0, kOilTemperature = 1, kBoxTemperature = 2;

/// The notes with the alarm code since `cursor` was made, in order.
std::vector<std::string> alarm_notes(EventCursor& cursor) {
  std::vector<std::string> out;
  for (const ControllerEvent& e : cursor.next(1 << 16)) {
    if (e.kind == ControllerEventKind::Note && e.code == "control.process-alarm") out.push_back(e.text);
  }
  return out;
}

TEST(AlarmScenario, AMessageAlarmWarnsAndTheProgramGoesOn) {
  Scenario s(edm_profile());
  s.on(control::Mode::Auto);
  TempProgram p("cut.ngc", kCut);
  EventCursor log(s.rig().controller().events());
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  s.ticks(500);
  s.sim().drift_analog_input(kBoxTemperature, 75, 20);  // 35 → 75 °C in 2 s: past 70 after 1.75 s
  ASSERT_TRUE(s.until([&] { return (s.status().servo.alarms_active & (1u << 2)) != 0; }, 3000));
  EXPECT_EQ(s.status().servo.state, control::State::Running);
  s.sim().drift_analog_input(kBoxTemperature, 60, 20);  // clears below 67 (70 less the hysteresis)
  ASSERT_TRUE(s.until([&] { return s.status().servo.alarms_active == 0; }, 3000));
  EXPECT_LE(s.sim().analog_input(kBoxTemperature), 67.0);
  EXPECT_GT(s.sim().analog_input(kBoxTemperature), 66.9);
  ASSERT_TRUE(s.until([&] { return !s.status().run_active; }, 10000));
  EXPECT_EQ(s.status().runs_finished, 1u) << "the program ran to its end";
  const std::vector<std::string> notes = alarm_notes(log);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0].rfind("alarm resistor_box_temperature: input 2 reads 70.0", 0), 0u) << notes[0];
  EXPECT_NE(notes[0].find("above its high bound of 70 °C: message only"), std::string::npos) << notes[0];
  EXPECT_NE(notes[1].find("is back in range"), std::string::npos) << notes[1];
}

TEST(AlarmScenario, AFeedHoldAlarmHoldsUntilTheInputIsBackByTheHysteresis) {
  Scenario s(edm_profile());
  s.on(control::Mode::Auto);
  TempProgram p("cut.ngc", kCut);
  EventCursor log(s.rig().controller().events());
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  s.ticks(1000);
  s.sim().set_analog_input(kOilTemperature, 40.5);
  ASSERT_TRUE(s.until(
      [&] { return s.status().servo.state == control::State::Held && s.status().servo.path_velocity == 0; },
      2000));
  const double x = s.status().servo.commanded[Axis::X];
  EXPECT_GT(x, 5.0);
  EXPECT_LT(x, 20.0) << "held on the path";
  s.sim().set_analog_input(kOilTemperature, 39.5);  // below the bound, not by the hysteresis
  s.ticks(10);
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::CycleStart)).refusal, control::Refusal::Interlock);
  EXPECT_EQ(s.status().servo.state, control::State::Held);
  s.sim().set_analog_input(kOilTemperature, 38.9);
  s.ticks(10);
  EXPECT_EQ(s.status().servo.alarms_active, 0u);
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return !s.status().run_active; }, 10000));
  EXPECT_EQ(s.status().runs_finished, 1u);
  EXPECT_EQ(s.report().max_following_error_mm < 0.5, true);
  const std::vector<std::string> notes = alarm_notes(log);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(
      notes[0].find(
          "alarm dielectric_temperature: input 1 reads 40.50 °C, above its high bound of 40 °C: feed hold"),
      std::string::npos)
      << notes[0];
}

TEST(AlarmScenario, AStopAlarmFaultsAndResetWaitsForTheLevel) {
  Scenario s(edm_profile());
  s.on(control::Mode::Auto);
  TempProgram p("cut.ngc", kCut);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  s.ticks(500);
  s.sim().drift_analog_input(kLevel, 30, 50);  // 80 → 30 mm in 1 s: below 40 after 0.8 s
  ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::Faulted; }, 2000));
  EXPECT_LE(s.sim().analog_input(kLevel), 40.0);
  EXPECT_GT(s.sim().analog_input(kLevel), 39.8) << "within two periods (0.05 mm each) of the crossing";
  EXPECT_FALSE(s.status().run_active);
  EXPECT_EQ(s.status().servo.fault.kind, control::FaultKind::ProcessAlarm);
  EXPECT_EQ(s.status().fault_text.rfind("alarm dielectric_level: input 0 reads", 0), 0u)
      << s.status().fault_text;
  EXPECT_NE(s.status().fault_text.find("below its low bound of 40 mm: the machine stopped"),
            std::string::npos);
  ASSERT_TRUE(s.until([&] { return s.sim().analog_input(kLevel) == 30; }, 2000));
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::Reset)).refusal, control::Refusal::FaultPersists);
  s.sim().set_analog_input(kLevel, 41);  // above the bound, not by the hysteresis
  s.ticks(5);
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::Reset)).refusal, control::Refusal::FaultPersists);
  s.sim().set_analog_input(kLevel, 43);
  s.ticks(5);
  s.must(Request::simple(control::CommandKind::Reset));
  s.must(Request::simple(control::CommandKind::MachineOn));
  s.ticks(5);
  EXPECT_EQ(s.status().servo.state, control::State::Idle);
}

TEST(AlarmScenario, AMachineSwitchedOnWithTheLevelLowFaultsAgain) {
  Scenario s(edm_profile());
  s.sim().set_analog_input(kLevel, 10);
  s.ticks(5);
  EXPECT_EQ(s.status().servo.alarms_active, 1u);
  s.ask(Request::simple(control::CommandKind::MachineOn));
  s.ticks(5);
  EXPECT_EQ(s.status().servo.state, control::State::Faulted);
}

}  // namespace
}  // namespace opencnc::controller::test
