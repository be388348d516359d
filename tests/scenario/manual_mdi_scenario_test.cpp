// SPDX-License-Identifier: GPL-3.0-or-later
// The controller's API in Manual and MDI mode: jogs and homing through requests, MDI lines that
// keep their modal state and start where the machine stands, faults reported in words.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "../control/test_profiles.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

TEST(MdiScenario, LinesRunOneAfterAnotherWithTheirModalState) {
  Scenario s(control::test::mill());
  s.on(control::Mode::Mdi);
  s.must(Request::mdi("G21 G90 G0 X10 Y5"));
  ASSERT_TRUE(s.idle());
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 10.0, 1e-9);
  EXPECT_NEAR(s.status().servo.commanded[Axis::Y], 5.0, 1e-9);
  s.must(Request::mdi("G1 X20 F600"));
  ASSERT_TRUE(s.idle());
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 20.0, 1e-9);
  s.must(Request::mdi("G91"));  // modal: the next line is incremental
  ASSERT_TRUE(s.idle());
  s.forget_samples();
  s.must(Request::mdi("X-5"));  // and still G1 at F600
  ASSERT_TRUE(s.idle());
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 15.0, 1e-9);
  double fastest = 0;  // still F600: 10 mm/s
  for (std::size_t i = 1; i < s.samples().size(); ++i)
    fastest = std::max(
        fastest, std::fabs(s.samples()[i].commanded[Axis::X] - s.samples()[i - 1].commanded[Axis::X]) / 1e-3);
  EXPECT_NEAR(fastest, 10.0, 1e-6);
  s.must(Request::mdi("S2000 M3"));  // the line ends once the spindle is at speed (0.5 s)
  ASSERT_TRUE(s.idle(20000));
  EXPECT_EQ(s.status().servo.spindle_direction, machine::SpindleDirection::Clockwise);
  EXPECT_TRUE(s.status().servo.spindle_at_speed);
  EXPECT_NEAR(s.status().servo.spindle_rpm_actual, 2000, 2000 * 0.02);
}

TEST(MdiScenario, AfterAJogIncrementalLinesStartWhereTheMachineIs) {
  Scenario s(control::test::mill());
  s.on(control::Mode::Mdi);
  s.must(Request::mdi("G91 G1 X1 F600"));
  ASSERT_TRUE(s.idle());
  s.must(Request::set_mode(control::Mode::Manual));
  s.must(Request::jog_by(Axis::X, 10, 50));
  ASSERT_TRUE(s.idle());
  s.must(Request::set_mode(control::Mode::Mdi));
  s.must(Request::mdi("X1"));  // G91 G1 still: 11 + 1
  ASSERT_TRUE(s.idle());
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 12.0, 1e-9);
}

TEST(MdiScenario, BadLinesAndWrongModesAreRefused) {
  Scenario s(control::test::mill());
  s.on(control::Mode::Manual);
  EXPECT_EQ(s.ask(Request::mdi("G0 X1")).refusal, control::Refusal::WrongMode);
  s.must(Request::set_mode(control::Mode::Mdi));
  const Outcome o = s.ask(Request::mdi("G1 X1 Q"));
  EXPECT_EQ(o.refusal, control::Refusal::ProgramError);
  ASSERT_FALSE(o.diagnostics.items().empty());
  EXPECT_EQ(o.diagnostics.items().front().file, "<mdi>");
  const Outcome far = s.ask(Request::mdi("G0 X5000"));  // beyond the 2000 mm soft limit
  EXPECT_EQ(far.refusal, control::Refusal::SoftLimit);
  s.ticks(50);
  EXPECT_EQ(s.status().servo.commanded, Pose{});
  EXPECT_EQ(s.ask(Request::jog(Axis::X, 10)).refusal, control::Refusal::WrongMode);
}

// A newcomer's first minutes (issue 29): after homing or a jog the machine is in Manual; cycle
// start runs the open program (the mode follows, as LinuxCNC's AXIS does), and the refusals that
// used to say "nothing to do in this state" say what the matter is.
TEST(ManualScenario, CycleStartInManualRunsTheOpenProgramAndRefusalsSayWhy) {
  TempProgram p("part.ngc", "G21 G90\nG1 X10 F600\nM2\n");
  Scenario s(control::test::mill());
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::set_mode(control::Mode::Manual));
  s.must(Request::jog_by(Axis::Y, 2, 20));
  ASSERT_TRUE(s.until([&] { return s.idle(); }, 5000));
  s.must(Request::simple(control::CommandKind::CycleStart));
  EXPECT_EQ(s.status().servo.mode, control::Mode::Auto);
  ASSERT_TRUE(s.until([&] { return !s.status().run_active && s.status().runs_finished == 1; }, 20000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 10.0, 1e-9);
  EXPECT_NEAR(s.status().servo.commanded[Axis::Y], 2.0, 1e-9);  // from where the jog left it
  Outcome o = s.ask(Request::simple(control::CommandKind::MachineOn));
  EXPECT_EQ(o.refusal, control::Refusal::NotApplicable);
  EXPECT_EQ(o.message, "the machine is already on");
  o = s.ask(Request::simple(control::CommandKind::FeedHold));
  EXPECT_EQ(o.message, "nothing is running to hold");
  s.must(Request::set_mode(control::Mode::Mdi));
  o = s.ask(Request::jog(Axis::X, 10));
  EXPECT_EQ(o.refusal, control::Refusal::WrongMode);
  EXPECT_EQ(o.message, "that is done in Manual mode: switch to MANUAL first");
}

TEST(ManualScenario, CycleStartWithoutAProgramSaysToOpenOne) {
  Scenario s(control::test::mill());
  s.on(control::Mode::Manual);
  const Outcome o = s.ask(Request::simple(control::CommandKind::CycleStart));
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("open one"), std::string::npos) << o.message;
  EXPECT_EQ(s.status().servo.mode, control::Mode::Manual);
}

TEST(ManualScenario, JogThroughTheControllerAndStopAtTheLimit) {
  Scenario s(control::test::mill({"axis.y.max_limit=12.0"}));
  s.on(control::Mode::Manual);
  s.must(Request::jog(Axis::Y, 40));
  ASSERT_TRUE(s.idle(5000));
  EXPECT_EQ(s.status().servo.commanded[Axis::Y], 12.0);
  s.must(Request::jog(Axis::Y, -40));
  s.ticks(100);
  s.must(Request::jog_stop(Axis::Y));
  ASSERT_TRUE(s.idle(5000));
  EXPECT_LT(s.status().servo.commanded[Axis::Y], 12.0);
  s.must(Request::jog_by(Axis::Y, 100, 40));  // clamped at the limit
  ASSERT_TRUE(s.idle(5000));
  EXPECT_EQ(s.status().servo.commanded[Axis::Y], 12.0);
}

TEST(ManualScenario, ManualSpindleAndCoolant) {
  Scenario s(control::test::mill());
  s.on(control::Mode::Manual);
  s.must(Request::spindle_on(1200, true));
  s.must(Request::coolant(control::Coolant::Flood, true));
  s.ticks(2000);
  EXPECT_NEAR(s.status().servo.spindle_rpm_actual, 1200, 30);
  EXPECT_TRUE(s.status().servo.flood);
  s.must(Request::simple(control::CommandKind::SpindleOff));
  s.must(Request::simple(control::CommandKind::EStop));  // e-stop also stops coolant
  s.ticks(2);
  EXPECT_FALSE(s.status().servo.flood);
  EXPECT_EQ(s.status().servo.spindle_direction, machine::SpindleDirection::Stopped);
}

TEST(ManualScenario, FaultsAreReportedInWordsNamingTheAxis) {
  Scenario s(control::test::mill({"power.ups=true"}));
  s.on(control::Mode::Manual);
  s.sim().set_amp_fault(1, true);
  s.ticks(3);
  const ControllerStatus st = s.status();
  EXPECT_EQ(st.servo.state, control::State::Faulted);
  EXPECT_NE(st.fault_text.find("Y drive"), std::string::npos) << st.fault_text;
  bool noted = false;
  EventCursor events(s.rig().controller().events(), true);
  for (const ControllerEvent& e : events.next())
    noted = noted || (e.kind == ControllerEventKind::Note && e.code == "control.fault.amplifier");
  EXPECT_TRUE(noted);
  s.sim().set_amp_fault(1, false);
  s.ticks(2);
  s.must(Request::simple(control::CommandKind::Reset));
  s.must(Request::simple(control::CommandKind::MachineOn));
  s.sim().set_mains_ok(false);
  s.ticks(3);
  EXPECT_EQ(s.status().servo.fault.kind, control::FaultKind::PowerLoss);
  EXPECT_NE(s.status().fault_text.find("power failure"), std::string::npos);
}

}  // namespace
}  // namespace opencnc::controller::test
