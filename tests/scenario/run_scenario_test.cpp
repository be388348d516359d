// SPDX-License-Identifier: GPL-3.0-or-later
// Whole programs through the whole controller on the simulated machine: to the end within the
// limits, feed hold in a blend, abort, e-stop, soft-limit preflight, overrides, single block,
// M1, machine I/O of the program (spindle, coolant, outputs, tool change, M66), probing, and
// bit-for-bit repeatable runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>
#include <string>

#include "../control/test_profiles.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

/// Square, arc, helix, spindle, coolant, an output, a dwell.
const char* kPart = R"(G21 G90 G17 G64 P0.01
S3000 M3
M8
G0 X10 Y10 Z5
G1 Z-1 F600
M62 P1
G1 X60 F3000
G2 X80 Y30 I0 J20
G3 X60 Y50 Z-2 I-20 J0
G1 X10
M63 P1
G4 P0.2
G1 Y10
G0 Z5
M9
M5
M2
)";

TEST(RunScenario, ProgramRunsToTheEndWithinTheLimits) {
  Scenario s(control::test::mill());
  TempProgram p("part.ngc", kPart);
  s.on(control::Mode::Auto);
  ASSERT_TRUE(s.run_file(p.path())) << s.message();
  const ControllerStatus st = s.status();
  EXPECT_EQ(st.servo.state, control::State::Idle);
  EXPECT_NEAR(st.servo.commanded[Axis::Z], 5.0, 1e-9);
  EXPECT_FALSE(st.servo.flood);
  EXPECT_EQ(st.servo.digital_out, 0u);
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(r.axes[static_cast<std::size_t>(i)].max_velocity, 100 * (1 + 1e-6));
    EXPECT_LE(r.axes[static_cast<std::size_t>(i)].max_acceleration, 1000 * (1 + 1e-6));
  }
  EXPECT_LE(r.max_command_contour_error_mm, 0.01 + 1e-6);  // G64 P0.01
  EXPECT_LE(r.max_contour_error_mm, 0.05);                 // the drives follow within tens of µm
  EXPECT_LE(r.max_following_error_mm, 0.05);
  EXPECT_GT(r.max_following_error_mm, 0.0);
  // The spindle ran up (2 s to 3000 rpm at 4000 rpm/s is 0.75 s) before the first cut, and the
  // dwell waited: the run takes longer than its moves.
  EXPECT_GT(r.machining_time_s, r.motion_time_s);
  // M62 P1 switched output 1 on exactly while the cut from X10 to X60 ... X10 ran.
  bool seen_on = false;
  for (const control::TraceSample& t : s.samples()) seen_on = seen_on || t.line == 7;
  EXPECT_TRUE(seen_on);
}

// G64 without P takes the profile's default tolerance (here 0.01 mm), in an inch program as in a
// metric one.
TEST(RunScenario, DefaultToleranceAppliesInInchProgramsToo) {
  for (const char* units : {"G21", "G20"}) {
    Scenario s(control::test::mill({"planner.default_tolerance=0.01"}));
    const double side = std::string(units) == "G20" ? 2.0 : 50.8;
    TempProgram p("sq.ngc",
                  fmt::format("{} G90 G64\nG0 X0 Y0\nG1 X{} F200\nY{}\nX0\nY0\nM2\n", units, side, side));
    s.on(control::Mode::Auto);
    ASSERT_TRUE(s.run_file(p.path())) << s.message();
    const RunReport r = s.report();
    EXPECT_LE(r.max_command_contour_error_mm, 0.01 + 1e-6) << units;
    EXPECT_GT(r.max_command_contour_error_mm, 0.005) << units;  // the corners were blended
  }
}

// The shipped mill has no default tolerance: G64 without P blends as large as the moves and the
// speed ask (as LinuxCNC does), within every limit.
TEST(RunScenario, ShippedMillBlendsWithoutABoundUnderG64WithoutP) {
  Scenario s(control::test::mill());
  TempProgram p("sq.ngc", "G21 G90 G64\nG0 X0 Y0\nG1 X50 F6000\nY50\nX0\nY0\nM2\n");
  s.on(control::Mode::Auto);
  ASSERT_TRUE(s.run_file(p.path())) << s.message();
  const RunReport r = s.report();
  EXPECT_GT(r.max_command_contour_error_mm, 0.5);  // a blend of several mm at 100 mm/s
  EXPECT_EQ(r.limit_violations, 0u);
}

TEST(RunScenario, OutputsFollowThePathMarkers) {
  Scenario s(control::test::mill());
  TempProgram p("io.ngc", "G0 X0 Y0\nF3000\nM64 P2\nG1 X10\nM62 P0\nG1 X20\nM63 P0\nG1 X30\nM65 P2\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  std::vector<std::pair<double, std::uint64_t>> changes;
  std::uint64_t last = 0;
  ASSERT_TRUE(s.until(
      [&] {
        const control::ServoStatus& v = s.status().servo;
        if (v.digital_out != last) changes.emplace_back(v.commanded[Axis::X], v.digital_out);
        last = v.digital_out;
        return !s.status().run_active && v.state == control::State::Idle;
      },
      20000));
  ASSERT_EQ(changes.size(), 4u);
  EXPECT_NEAR(changes[0].first, 0.0, 0.01);  // M64 P2 before the first move
  EXPECT_EQ(changes[0].second, 4u);
  EXPECT_NEAR(changes[1].first, 10.0, 0.01);  // M62 P0 as the path passes X10
  EXPECT_EQ(changes[1].second, 5u);
  EXPECT_NEAR(changes[2].first, 20.0, 0.05);
  EXPECT_EQ(changes[2].second, 4u);
  EXPECT_EQ(changes[3].second, 0u);
}

// Feed hold in the blend of a corner: the motion stops on the blended path and goes on from
// there; the commanded position never jumps.
TEST(RunScenario, FeedHoldInABlendThenResumeStaysOnThePath) {
  Scenario s(control::test::mill());
  TempProgram p("sq.ngc", "G21 G90 G64 P0.5\nG0 X0 Y0\nF1200\nG1 X100\nY100\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  // At 20 mm/s the corner is a fillet of about 0.42 mm radius (the speed's centripetal limit):
  // hold as the path enters it, so that the stop (0.2 mm) lands inside.
  ASSERT_TRUE(s.until([&] { return s.status().servo.commanded[Axis::X] > 99.6; }, 10000));
  s.must(Request::simple(control::CommandKind::FeedHold));
  ASSERT_TRUE(s.until([&] { return s.status().servo.motion == traj::RunState::Held; }, 5000));
  EXPECT_EQ(s.status().servo.state, control::State::Held);
  const Pose held = s.status().servo.commanded;
  EXPECT_GT(held[Axis::Y], 0.0);  // inside the blend
  EXPECT_LT(held[Axis::X], 100.0);
  s.ticks(300);
  EXPECT_EQ(s.status().servo.commanded, held);
  s.must(Request::simple(control::CommandKind::Resume));
  ASSERT_TRUE(s.idle(20000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::Y], 100.0, 1e-9);
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u);
  EXPECT_LE(r.max_command_contour_error_mm, 0.5 + 1e-6);
  for (std::size_t i = 1; i < s.samples().size(); ++i) {  // continuous: at most v·T per period
    const Pose& a = s.samples()[i - 1].commanded;
    const Pose& b = s.samples()[i].commanded;
    EXPECT_LE(std::hypot(b[0] - a[0], b[1] - a[1]), 0.02 * (1 + 1e-6)) << i;
  }
}

TEST(RunScenario, AbortIsAControlledStopOnThePath) {
  Scenario s(control::test::mill());
  TempProgram p("line.ngc", "G0 X0 Y0\nG1 X100 Y50 F6000\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.commanded[Axis::X] > 30; }, 10000));
  s.must(Request::simple(control::CommandKind::Abort));
  ASSERT_TRUE(s.idle(5000));
  const Pose at = s.status().servo.commanded;
  EXPECT_LT(at[Axis::X], 100.0);
  EXPECT_NEAR(at[Axis::Y], at[Axis::X] / 2, 1e-9);  // on the line
  EXPECT_FALSE(s.status().run_active);
  EXPECT_EQ(s.rig().channels().blocks.available(), 0u);
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u);
  // Cycle start runs the program again, from where the machine stands.
  ASSERT_TRUE(s.start_and_finish());
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 100.0, 1e-9);
}

TEST(RunScenario, EstopMidMoveRefusesMotionUntilReset) {
  Scenario s(control::test::mill());
  TempProgram p("line.ngc", "G1 X100 F3000\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  s.ticks(300);
  s.must(Request::simple(control::CommandKind::EStop));
  s.ticks(2);
  EXPECT_EQ(s.status().servo.state, control::State::EStopped);
  EXPECT_FALSE(s.status().run_active);
  const Outcome o = s.ask(Request::simple(control::CommandKind::CycleStart));
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.refusal, control::Refusal::EStopActive);
  s.ticks(2000);  // the axes coast to rest without power; the command follows them
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], s.status().servo.actual[Axis::X], 1e-9);
  EXPECT_EQ(s.rig().machine().joint(0).velocity(), 0.0);
  s.must(Request::simple(control::CommandKind::Reset));
  s.must(Request::simple(control::CommandKind::MachineOn));
  ASSERT_TRUE(s.start_and_finish());
}

TEST(RunScenario, SoftLimitPreflightRejectsTheProgramAndNothingMoves) {
  Scenario s(control::test::mill({"axis.x.max_limit=45.0"}));
  // The arc's end points are inside, its extent is not: centre (40, 10), radius 10 reaches X50.
  TempProgram p("bulge.ngc", "G0 X40 Y0\nG3 X40 Y20 I0 J10 F1000\nM2\n");
  s.on(control::Mode::Auto);
  const Outcome o = s.ask(Request::open(p.path()));
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.refusal, control::Refusal::SoftLimit);
  const Diagnostic* err = nullptr;
  for (const Diagnostic& x : o.diagnostics.items()) {
    if (x.severity == Severity::Error && err == nullptr) err = &x;
  }
  ASSERT_NE(err, nullptr);
  const Diagnostic& d = *err;
  EXPECT_EQ(d.code, "control.soft-limit");
  EXPECT_EQ(d.line, 2u);
  EXPECT_NE(d.file.find("bulge.ngc"), std::string::npos);
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::CycleStart)).refusal, control::Refusal::NoProgram);
  s.ticks(100);
  for (const control::TraceSample& t : s.samples()) EXPECT_EQ(t.commanded, Pose{});
}

TEST(RunScenario, FeedOverrideScalesTheFeedAndZeroHolds) {
  Scenario s(control::test::mill());
  TempProgram p("slow.ngc", "G1 X20 F600\nM2\n");  // 10 mm/s: 2 s
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::feed_override(0.5));
  ASSERT_TRUE(s.start_and_finish());
  const RunReport half = s.report();
  EXPECT_NEAR(half.motion_time_s, 4.0, 0.02);
  EXPECT_NEAR(half.axes[0].max_velocity, 5.0, 1e-6);
  s.must(Request::feed_override(2.0));
  ASSERT_TRUE(s.run_file(p.path()));  // from X20 back... no: the same absolute end, so no motion
  s.must(Request::feed_override(0.0));
  TempProgram back("back.ngc", "G1 X0 F600\nM2\n");
  s.must(Request::open(back.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  s.ticks(500);
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 20.0);  // 0 %: nothing moves
  s.must(Request::feed_override(2.0));
  ASSERT_TRUE(s.idle(5000));
  const RunReport twice = s.report();
  EXPECT_NEAR(twice.axes[0].max_velocity, 20.0, 1e-6);
  EXPECT_EQ(s.ask(Request::feed_override(2.5)).refusal, control::Refusal::BadValue);
}

TEST(RunScenario, RapidOverrideScalesRapids) {
  Scenario s(control::test::mill());
  TempProgram p("rapid.ngc", "G0 X50\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::rapid_override(0.25));
  ASSERT_TRUE(s.run_file(p.path()));
  const RunReport r = s.report();
  EXPECT_NEAR(r.axes[0].max_velocity, 25.0, 1e-6);
}

TEST(RunScenario, SingleBlockStopsAfterEveryMove) {
  Scenario s(control::test::mill());
  TempProgram p("three.ngc", "G61\nG1 X10 F3000\nY10\nX0\nM2\n");  // exact path: stops at the ends
  s.on(control::Mode::Auto);
  s.must(Request::single_block(true));
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  const Pose ends[] = {[] {
                         Pose q;
                         q[0] = 10;
                         return q;
                       }(),
                       [] {
                         Pose q;
                         q[0] = 10;
                         q[1] = 10;
                         return q;
                       }()};
  for (const Pose& end : ends) {
    ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::Stopped; }, 10000));
    EXPECT_EQ(s.status().servo.stop_reason, control::StopReason::SingleBlock);
    EXPECT_NEAR(s.status().servo.commanded[Axis::X], end[Axis::X], 1e-9);
    EXPECT_NEAR(s.status().servo.commanded[Axis::Y], end[Axis::Y], 1e-9);
    s.must(Request::simple(control::CommandKind::CycleStart));
  }
  s.must(Request::single_block(false));
  ASSERT_TRUE(s.idle(10000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 0.0, 1e-9);
}

TEST(RunScenario, OptionalStopWaitsOnlyWhenTheSwitchIsOn) {
  TempProgram p("m1.ngc", "G1 X5 F3000\nM1\nG1 X10\nM2\n");
  for (const bool on : {false, true}) {
    Scenario s(control::test::mill());
    s.on(control::Mode::Auto);
    s.must(Request::optional_stop(on));
    s.must(Request::open(p.path()));
    s.must(Request::simple(control::CommandKind::CycleStart));
    const bool stopped = s.until([&] { return s.status().servo.state == control::State::Stopped; }, 3000);
    EXPECT_EQ(stopped, on);
    if (on) {
      EXPECT_EQ(s.status().servo.stop_reason, control::StopReason::OptionalStop);
      EXPECT_NEAR(s.status().servo.commanded[Axis::X], 5.0, 1e-9);
      s.must(Request::simple(control::CommandKind::CycleStart));
    }
    ASSERT_TRUE(s.idle(5000));
    EXPECT_NEAR(s.status().servo.commanded[Axis::X], 10.0, 1e-9);
  }
}

TEST(RunScenario, ProgramStopAndBlockDelete) {
  Scenario s(control::test::mill());
  TempProgram p("m0.ngc", "G1 X5 F3000\n/G1 Y5\nM0\nG1 X10\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::block_delete(true));
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.state == control::State::Stopped; }, 5000));
  EXPECT_EQ(s.status().servo.stop_reason, control::StopReason::ProgramStop);
  EXPECT_EQ(s.status().servo.commanded[Axis::Y], 0.0);  // the '/' line was skipped
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.idle(5000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 10.0, 1e-9);
}

/// A tool table with tools 3 and 7, as a profile override.
std::string tool_table(const TempProgram& t) {
  return "interpreter.tool_table=\"" + t.path() + "\"";
}

TEST(RunScenario, ManualToolChangeWaitsForTheOperator) {
  TempProgram tools("tools.tbl", "T3 P3 Z0\nT7 P7 Z0\n");
  Scenario s(control::test::mill({tool_table(tools)}));
  TempProgram p("tool.ngc", "T3 M6\nG1 X5 F3000\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.wait == control::Wait::ManualToolChange; }, 2000));
  s.ticks(500);
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 0.0);
  s.must(Request::simple(control::CommandKind::ToolChanged));
  ASSERT_TRUE(s.idle(5000));
  EXPECT_EQ(s.status().servo.tool, 3);
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 5.0, 1e-9);
}

// With [tool_change] position the M6 retracts Z first, then goes across, in machine coordinates
// (G54 and the tool length do not shift it); the operator changes the tool there, and the
// program's next move starts from there.
TEST(RunScenario, M6GoesToTheToolChangePositionAndTheOperatorChangesThere) {
  TempProgram tools("tools.tbl", "T3 P3 Z20\nT7 P7 Z0\n");
  Scenario s(control::test::mill({tool_table(tools), "tool_change.position={X=-50,Z=100}"}));
  TempProgram p("tool.ngc",
                "G64 P0.01\nG10 L2 P1 X10 Z-5\nG54 G0 Z2\nG0 Y10\nG0 X20\nT3 M6 G43\nG0 Z5\nG91 G0 X1\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  // The program goes to machine X30 Y10 Z-3 (its last move across at Z-3); then Z rises to 100
  // and only then does X go back to -50: X does not fall while Z is under 100, and the path
  // keeps to the corner into the rise (blended within the program's G64 P0.01, as any G0 of its
  // own there would be).
  double corner_mm = 0, x_max = 0, x_fell_mm = 0;
  bool down = false;  // Z has come down to -3
  ASSERT_TRUE(s.until(
      [&] {
        const Pose c = s.status().servo.commanded;
        down = down || std::abs(c[Axis::Z] + 3.0) < 1e-9;
        if (down && c[Axis::Z] < 100.0 - 1e-9) {
          x_max = std::max(x_max, c[Axis::X]);
          x_fell_mm = std::max(x_fell_mm, x_max - c[Axis::X]);
          if (c[Axis::X] <= 30.0)
            corner_mm = std::max(corner_mm, std::min(30.0 - c[Axis::X], c[Axis::Z] + 3.0));
        }
        return s.status().servo.wait == control::Wait::ManualToolChange;
      },
      10000));
  EXPECT_LE(corner_mm, 0.01 + 1e-9);
  EXPECT_EQ(x_fell_mm, 0.0);
  EXPECT_NEAR(x_max, 30.0, 1e-9);
  s.ticks(200);
  Pose at = s.status().servo.commanded;
  EXPECT_NEAR(at[Axis::X], -50.0, 1e-9);
  EXPECT_NEAR(at[Axis::Y], 10.0, 1e-9);  // not named: it stays
  EXPECT_NEAR(at[Axis::Z], 100.0, 1e-9);
  s.must(Request::simple(control::CommandKind::ToolChanged));
  ASSERT_TRUE(s.idle(10000));
  at = s.status().servo.commanded;
  EXPECT_EQ(s.status().servo.tool, 3);
  EXPECT_NEAR(at[Axis::Z], 20.0, 1e-9);   // G0 Z5 under G54 Z-5 and T3's 20 mm
  EXPECT_NEAR(at[Axis::X], -49.0, 1e-9);  // G91 X1 from the tool-change position
}

// The preflight checks M6's moves like the program's own. A profile file cannot hold a
// tool-change position outside the soft limits (the loader refuses it at its key); one built past
// the loader shows the check: the program is refused at the M6's line and nothing moves.
TEST(RunScenario, ThePreflightChecksTheToolChangeMoves) {
  TempProgram tools("tools.tbl", "T3 P3 Z0\n");
  config::MachineProfile profile = control::test::mill({tool_table(tools)});
  profile.tool_change.axes = AxisMask::from_letters("Z");
  profile.tool_change.position[Axis::Z] = 2500;  // beyond Z's 2000
  Scenario s(profile);
  TempProgram p("tool.ngc", "G0 X5\nT3 M6\nG0 X6\nM2\n");
  s.on(control::Mode::Auto);
  const Outcome o = s.ask(Request::open(p.path()));
  EXPECT_FALSE(o.accepted);
  ASSERT_FALSE(o.diagnostics.items().empty());
  const Diagnostic& d = o.diagnostics.items().front();
  EXPECT_EQ(d.code, "control.soft-limit");
  EXPECT_EQ(d.line, 2u);
  EXPECT_NE(d.message.find("takes Z to 2500"), std::string::npos) << d.message;
  EXPECT_EQ(s.status().servo.commanded, Pose{});
}

TEST(RunScenario, WaitForInputReadsTheMachine) {
  Scenario s(control::test::mill());
  // M66 P1 L3 Q5: wait up to 5 s for input 1 high; then M66 P2 L1 Q0.1 times out.
  TempProgram p("m66.ngc", "M66 P1 L3 Q5\nG1 X5 F3000\nM66 P2 L1 Q0.1\nG1 X6\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.wait == control::Wait::Input; }, 2000));
  s.ticks(300);
  EXPECT_EQ(s.status().servo.commanded[Axis::X], 0.0);
  s.sim().set_digital_input(1, true);
  ASSERT_TRUE(s.idle(10000));
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 6.0, 1e-9);
  EXPECT_EQ(s.status().servo.input_value, -1.0);  // the second wait timed out
}

// Two waits in a row, with no motion between them: each does its own waiting (the second was once
// let through in the period after the first had ended).
TEST(RunScenario, TwoSyncMarkersInARowEachWait) {
  Scenario s(control::test::mill());
  TempProgram p("m66x2.ngc", "M66 P1 L3 Q5\nM66 P2 L3 Q0.5\nG1 X6 F3000\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().servo.wait == control::Wait::Input; }, 2000));
  s.sim().set_digital_input(1, true);
  const std::uint64_t t0 = s.rig().ticks();
  ASSERT_TRUE(s.until([&] { return s.status().servo.commanded[Axis::X] > 0; }, 10000));
  EXPECT_GE(s.rig().ticks() - t0, 500u);  // the second one waited its 0.5 s for input 2
  ASSERT_TRUE(s.idle(10000));
  EXPECT_EQ(s.status().servo.input_value, -1.0);
}

TEST(RunScenario, ToolChangerHandshake) {
  TempProgram tools("tools.tbl", "T3 P3 Z0\nT7 P7 Z0\n");
  Scenario s(control::test::homing_mill({tool_table(tools)}));
  s.on(control::Mode::Manual);
  s.must(Request::home());
  ASSERT_TRUE(s.idle(120000));
  s.must(Request::set_mode(control::Mode::Auto));
  TempProgram p("tc.ngc", "T7\nG1 X280 F3000\nM6\nG1 X270\nM2\n");
  s.must(Request::open(p.path()));
  ASSERT_TRUE(s.start_and_finish());
  EXPECT_EQ(s.status().servo.tool, 7);
  EXPECT_EQ(s.sim().cycle() > 0, true);
}

TEST(RunScenario, AutoIsRefusedUntilHomedThenRuns) {
  Scenario s(control::test::homing_mill());
  TempProgram p("p.ngc", "G1 X280 F3000\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  EXPECT_EQ(s.ask(Request::simple(control::CommandKind::CycleStart)).refusal, control::Refusal::NotHomed);
  s.must(Request::set_mode(control::Mode::Manual));
  s.must(Request::home());
  ASSERT_TRUE(s.idle(120000));
  s.must(Request::set_mode(control::Mode::Auto));
  ASSERT_TRUE(s.start_and_finish());
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 280.0, 1e-9);
}

// A probe move (G38.2, built from canonical calls: the interpreter's probing module is still to
// come) toward a part whose top the probe meets at machine Z −145 (the sim's probe window is at
// table −100, and homing put machine Z at table − 45): the move stops there, the position is
// latched, and the rest of the program runs from where the machine stopped.
TEST(RunScenario, ProbeTripStopsTheMoveAndTheProgramGoesOn) {
  Scenario s(control::test::homing_mill());
  s.on(control::Mode::Manual);
  s.must(Request::home());
  ASSERT_TRUE(s.idle(120000));
  s.must(Request::set_mode(control::Mode::Auto));
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"), s.status().servo.commanded);
  Pose at = s.status().servo.commanded;
  b.set_feed_rate(300);
  at[Axis::Z] = -180;
  b.straight_probe(0, at);
  at[Axis::Z] = -100;
  b.straight_traverse(1, at);
  at[Axis::X] = 280;
  b.straight_traverse(2, at);
  b.program_end();
  s.must(Request::open(std::make_shared<canon::Program>(b.take()), "probe"));
  ASSERT_TRUE(s.start_and_finish());
  const control::ServoStatus& v = s.status().servo;
  ASSERT_TRUE(v.probe_tripped);
  EXPECT_NEAR(v.probe_position[Axis::Z], -145.0, 0.01);
  double lowest = 0;
  for (const control::TraceSample& t : s.samples()) lowest = std::min(lowest, t.commanded[Axis::Z]);
  EXPECT_GT(lowest, -145.0 - 0.05);  // stopped within the braking distance at 5 mm/s
  EXPECT_NEAR(v.commanded[Axis::Z], -100.0, 1e-9);
  EXPECT_NEAR(v.commanded[Axis::X], 280.0, 1e-9);
}

TEST(RunScenario, VirtualTimeRunsAreBitForBitRepeatable) {
  TempProgram p("part.ngc", kPart);
  std::vector<control::TraceSample> first;
  for (int run = 0; run < 2; ++run) {
    Scenario s(control::test::mill());
    s.on(control::Mode::Auto);
    s.must(Request::feed_override(1.3));
    ASSERT_TRUE(s.run_file(p.path()));
    if (run == 0) {
      first = s.samples();
      continue;
    }
    ASSERT_EQ(s.samples().size(), first.size());
    EXPECT_EQ(std::memcmp(s.samples().data(), first.data(), first.size() * sizeof(control::TraceSample)), 0);
  }
}

}  // namespace
}  // namespace opencnc::controller::test
