// SPDX-License-Identifier: GPL-3.0-or-later
// Run from line: the line resolved to its first move, the approach there, the program resumed
// with the state it has at that line (a G55 offset set before it); lines that make no move, lie
// past the end or after an input are refused with words and move nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "../control/test_profiles.hpp"
#include "opencnc/controller/run_from_line.hpp"
#include "scenario.hpp"

namespace opencnc::control::test {
namespace {

constexpr const char* kProgram =
    "G21 G90 F600\n"      // 1
    "G10 L2 P2 X10\n"     // 2
    "G55 G0 X0 Y0 Z5\n"   // 3
    "G1 Z0\n"             // 4
    "G1 X20\n"            // 5
    "G1 Y20\n"            // 6
    "G1 X0\n"             // 7
    "G0 Z5\n"             // 8
    "o<unused> sub\n"     // 9
    "  G1 X99\n"          // 10
    "o<unused> endsub\n"  // 11
    "M2\n";               // 12

struct Rig {
  Rig() : s(mill()) {
    Diagnostics d;
    feature = std::make_shared<RunFromLineFeature>(GcodeProgramSource::create(mill(), d));
    EXPECT_TRUE(s.rig().controller().add_feature(feature));
    s.ticks(1);
  }
  Outcome run_from(std::uint32_t line) {
    return s.ask(Request::feature("run-from-line", "start", RunFromLineArgs{line}));
  }
  Scenario s;
  std::shared_ptr<RunFromLineFeature> feature;
};

TEST(RunFromLineScenario, TheProgramStartsAtTheLineWithItsStateAfterTheApproach) {
  TempProgram p("part.ngc", kProgram);
  Rig r;
  r.s.on(Mode::Auto);
  r.s.must(Request::open(p.path()));
  const Outcome o = r.run_from(6);
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_NE(o.message.find("part.ngc:6"), std::string::npos) << o.message;
  // The approach (an auxiliary job) to the start of line 6's move: machine X 30 (G55 X20), Y 0, Z 0.
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Auxiliary; }, 1000));
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Program; }, 100000));
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::X], 30.0, 1e-9);
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::Z], 0.0, 1e-9);
  // The program from line 6 on, never an earlier line, in G55.
  std::uint32_t first_line = 0;
  ASSERT_TRUE(r.s.until(
      [&] {
        const ControllerStatus st = r.s.status();
        if (first_line == 0 && st.job == JobKind::Program && st.location.line > 0)
          first_line = st.location.line;
        if (st.job == JobKind::Program && (st.location.line == 6 || st.location.line == 7)) {  // M2 sets G54
          EXPECT_EQ(st.offsets.system, 2);
        }
        return !st.run_active && st.servo.state == State::Idle;
      },
      200000));
  EXPECT_EQ(first_line, 6u);
  const Pose end = r.s.status().servo.commanded;
  EXPECT_NEAR(end[Axis::X], 10.0, 1e-9);  // G55 X0
  EXPECT_NEAR(end[Axis::Y], 20.0, 1e-9);
  EXPECT_NEAR(end[Axis::Z], 5.0, 1e-9);
}

TEST(RunFromLineScenario, LinesWithoutAMovePastTheEndOrAfterAnInputAreRefused) {
  TempProgram p("part.ngc", kProgram);
  Rig r;
  r.s.on(Mode::Auto);
  r.s.must(Request::open(p.path()));
  const Pose before = r.s.status().servo.commanded;
  Outcome o = r.run_from(10);  // in a subroutine that is never called
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("line 10 makes no move"), std::string::npos) << o.message;
  o = r.run_from(40);
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("line 40 is past the program's end (line 12; its last move is on line 8)"),
            std::string::npos)
      << o.message;
  o = r.run_from(0);
  EXPECT_EQ(o.refusal, Refusal::BadValue);
  r.s.ticks(50);
  EXPECT_FALSE(r.s.status().run_active);
  EXPECT_EQ(r.s.status().servo.commanded, before);

  TempProgram q("input.ngc", "G21 G90 F600\nG1 X5\nM66 P0 L0\nG1 X10\nM2\n");
  r.s.must(Request::open(q.path()));
  o = r.run_from(4);
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.message.find("after the input value at "), std::string::npos) << o.message;
  EXPECT_TRUE(r.run_from(2).accepted);                                                   // before it: fine
  ASSERT_TRUE(r.s.until([&] { return r.s.status().job == JobKind::Program; }, 100000));  // after the approach
  ASSERT_TRUE(r.s.idle(200000));
  EXPECT_NEAR(r.s.status().servo.commanded[Axis::X], 10.0, 1e-9);
  // Manual mode: refused
  r.s.must(Request::set_mode(Mode::Manual));
  EXPECT_EQ(r.run_from(2).refusal, Refusal::WrongMode);
}

}  // namespace
}  // namespace opencnc::control::test

namespace opencnc::control::test {
namespace {

// The approach's last leg runs at the line's move's feed per minute: under G93 the move's own
// (length × F), under G95 F × the spindle speed set before it; a G95 line under G96 (no rpm known)
// is refused.
TEST(RunFromLineScenario, TheApproachFeedIsPerMinuteUnderInverseTimeAndPerRevolution) {
  TempProgram p("feeds.ngc",
                "G21 G90 G94 F600\n"  // 1
                "S1000 M3\n"          // 2
                "G0 X0 Y0 Z5\n"       // 3
                "G1 Z0\n"             // 4
                "G93 G1 X30 F2\n"     // 5: 30 mm in 1/2 min: 60 mm/min
                "G95 G1 X40 F0.1\n"   // 6: 0.1 mm/rev at 1000 rpm: 100 mm/min
                "S2500\n"             // 7
                "G1 Y10\n"            // 8: 250 mm/min
                "G94 G1 X0 F300\n"    // 9
                "M2\n");              // 10
  Diagnostics d;
  const auto source = GcodeProgramSource::create(mill(), d);
  const double expected[][2] = {{4, 600}, {5, 60}, {6, 100}, {8, 250}, {9, 300}};
  for (const auto& [line, feed] : expected) {
    std::string why;
    const auto at = find_line_start(*source, p.path(), Pose{}, static_cast<std::uint32_t>(line), {}, &why);
    ASSERT_TRUE(at.has_value()) << why;
    EXPECT_NEAR(at->feed_mm_per_min, feed, 1e-9) << "line " << line;
  }
  TempProgram q("no-speed.ngc", "G21 G90 G96 S100 D3000 M3\nG95 G1 X5 F0.1\nM2\n");
  std::string why;
  EXPECT_FALSE(find_line_start(*source, q.path(), Pose{}, 2, {}, &why).has_value());
  EXPECT_NE(why.find("line 2 feeds per revolution (G95) and no spindle speed in rpm is set before it"),
            std::string::npos)
      << why;
}

}  // namespace
}  // namespace opencnc::control::test
