// SPDX-License-Identifier: GPL-3.0-or-later
// Jerk-limited axes through the whole controller: a streamed program moves exactly as the whole
// program planned at once, a feed hold inside a fitted run of short moves stops on the path and
// goes on from there, overrides changing mid-move and a probe's sync point keep every limit.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "../control/test_profiles.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

/// The shipped mill with J = 100 × A on every axis (1e5 mm/s³).
config::MachineProfile jerk_mill(std::vector<std::string> sets = {}) {
  for (const char* s : {"axis.x.max_jerk=100000", "axis.y.max_jerk=100000", "axis.z.max_jerk=100000"})
    sets.emplace_back(s);
  return control::test::mill(sets);
}

/// A dense spiral of short moves (CAM output, 0.1 µm coordinates) within G64 P0.01.
std::string dense_spiral(int moves) {
  std::string text = "G21 G90 G64 P0.01\nG0 X20 Y0\nF3000\n";
  for (int i = 1; i <= moves; ++i) {
    const double a = i * 0.01, r = 20 - 0.0005 * i;
    text += fmt::format("G1 X{:.4f} Y{:.4f}\n", r * std::cos(a), r * std::sin(a));
  }
  return text + "M2\n";
}

// The interpreter streaming into the planner (the least read-ahead: the planner asks) gives the
// trace of the same program interpreted up front and opened whole, sample for sample: the fitted
// runs, the held blends and the window's settling do not depend on how far the program was read.
TEST(JerkScenario, StreamingMovesExactlyAsTheWholeProgram) {
  TempProgram p("spiral.ngc", dense_spiral(3000));
  std::vector<control::TraceSample> streamed, whole;
  {
    Scenario s(jerk_mill({"interpreter.readahead_moves=10"}));
    s.on(control::Mode::Auto);
    ASSERT_TRUE(s.run_file(p.path(), 400000)) << s.message();
    streamed = s.samples();
    const RunReport r = s.report();
    EXPECT_EQ(r.limit_violations, 0u);
    EXPECT_LE(r.max_command_contour_error_mm, 0.01 + 1e-9);
  }
  {
    Scenario s(jerk_mill());
    s.on(control::Mode::Auto);
    gcode::Options o;
    o.axes = AxisMask::from_letters("XYZ");
    o.initial_units = canon::Units::Mm;
    o.user_units = canon::Units::Mm;
    o.extensions = gcode::standard_extensions(o.dialect);
    gcode::Interpreter interp(o);
    canon::ProgramBuilder b(o.axes, s.status().servo.commanded);
    b.program().set_sources(interp.sources());
    b.set_motion_control_mode(canon::MotionControl::Continuous, 0);
    ASSERT_TRUE(interp.open(p.path()));
    interp.start(b);
    ASSERT_EQ(interp.run(b), gcode::RunStatus::Finished);
    s.must(Request::open(std::make_shared<canon::Program>(b.take()), "spiral"));
    ASSERT_TRUE(s.start_and_finish(400000)) << s.message();
    whole = s.samples();
  }
  ASSERT_EQ(streamed.size(), whole.size());
  for (std::size_t i = 0; i < streamed.size(); ++i) {
    ASSERT_TRUE(streamed[i].commanded == whole[i].commanded && streamed[i].tick == whole[i].tick)
        << "sample " << i << " (move " << streamed[i].segment << ")";
  }
}

// A feed hold in the middle of the fitted spiral: the motion brakes with limited jerk on the
// path, stays, and goes on from there when resumed; no limit is passed, the path stays within P.
TEST(JerkScenario, FeedHoldInAFittedRunStopsOnThePathAndResumes) {
  Scenario s(jerk_mill());
  TempProgram p("spiral.ngc", dense_spiral(1500));
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(s.until([&] { return s.status().location.line > 700; }, 100000));
  s.must(Request::simple(control::CommandKind::FeedHold));
  ASSERT_TRUE(s.until([&] { return s.status().servo.motion == traj::RunState::Held; }, 5000));
  const Pose held = s.status().servo.commanded;
  s.ticks(200);
  EXPECT_EQ(s.status().servo.commanded, held);
  s.must(Request::simple(control::CommandKind::Resume));
  ASSERT_TRUE(s.idle(100000));
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u);
  EXPECT_LE(r.max_command_contour_error_mm, 0.01 + 1e-9);
}

// The feed override stepping while the motion runs (down, to zero, up to 200 %) and the rapid
// override: the jerk-limited generator follows within every limit.
TEST(JerkScenario, OverridesChangingMidMoveKeepTheLimits) {
  Scenario s(jerk_mill());
  TempProgram p("moves.ngc",
                "G21 G90 G64 P0.05\nG0 X0 Y0\nG1 X60 Y10 F3000\nG1 X60 Y60\nG3 X20 Y60 R20\nG0 X0 Y0\nM2\n");
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));
  const double steps[] = {0.5, 0.0, 2.0, 0.3, 1.2, 2.0};
  for (double f : steps) {
    s.ticks(150);
    s.must(Request::feed_override(f));
  }
  s.must(Request::rapid_override(0.4));
  ASSERT_TRUE(s.idle(100000));
  const RunReport r = s.report();
  EXPECT_EQ(r.limit_violations, 0u);
  EXPECT_LE(r.max_command_contour_error_mm, 0.05 + 1e-9);
  EXPECT_NEAR(s.status().servo.commanded[Axis::X], 0.0, 1e-9);
}

// A probe's sync point: the motion stops where the probe trips, the interpreter reads the result
// and the program goes on from it, the axes jerk-limited throughout.
TEST(JerkScenario, AProbeSyncPointStopsAndTheProgramGoesOnFromItsResult) {
  Scenario s(jerk_mill());
  TempProgram p("probe.ngc",
                "G21 G90 G54\nG0 X10 Y10 Z0\nG38.2 Z-100 F300\nG0 Z[#5063+5]\nG1 X20 F1200\nM2\n");
  s.on(control::Mode::Auto);
  ASSERT_TRUE(s.run_file(p.path())) << s.message();
  const ControllerStatus st = s.status();
  EXPECT_NEAR(st.servo.commanded[Axis::Z], -45.0, 0.001);
  EXPECT_NEAR(st.servo.commanded[Axis::X], 20.0, 1e-9);
  EXPECT_TRUE(st.servo.probe_tripped);
  EXPECT_EQ(s.report().limit_violations, 0u);
}

}  // namespace
}  // namespace opencnc::controller::test
