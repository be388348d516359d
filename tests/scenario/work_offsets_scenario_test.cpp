// SPDX-License-Identifier: GPL-3.0-or-later
// Work coordinates and distance to go in the controller's status: the offsets the interpreter
// applied to the move at the commanded position (G55, G92, G43), exactly as it applied them.
#include <gtest/gtest.h>

#include <string>

#include "../control/test_profiles.hpp"
#include "scenario.hpp"

namespace opencnc::controller::test {
namespace {

// Runs until the commanded X passes `x` on a move of `line`.
bool until_past(Scenario& s, std::uint32_t line, double x) {
  return s.until(
      [&] {
        const ControllerStatus st = s.status();
        return st.servo.line == line && st.servo.commanded[Axis::X] > x;
      },
      100000);
}

TEST(WorkOffsetsScenario, AG55OffsetAndAG92ShiftShowUpExactly) {
  TempProgram p("offsets.ngc",
                "G21 G90 F600\n"           // 1
                "G10 L2 P2 X10 Y20 Z-5\n"  // 2
                "G55\n"                    // 3
                "G0 X0 Y0 Z0\n"            // 4
                "G1 X30\n"                 // 5
                "G92 X0\n"                 // 6: X here (30) becomes 0
                "G1 X15\n"                 // 7
                "M2\n");
  Scenario s(control::test::mill());
  s.on(control::Mode::Auto);
  s.must(Request::open(p.path()));
  s.must(Request::simple(control::CommandKind::CycleStart));

  ASSERT_TRUE(until_past(s, 5, 20.0));
  ControllerStatus st = s.status();
  EXPECT_EQ(st.offsets.system, 2);
  EXPECT_STREQ(work_system_name(st.offsets.system), "G55");
  EXPECT_EQ(st.offsets.g5x[Axis::X], 10.0);
  EXPECT_EQ(st.offsets.g5x[Axis::Y], 20.0);
  EXPECT_EQ(st.offsets.g5x[Axis::Z], -5.0);
  EXPECT_EQ(st.offsets.g92, Pose{});
  Pose work = work_position(st.servo.commanded, st.offsets);
  EXPECT_EQ(work[Axis::X], st.servo.commanded[Axis::X] - 10.0);
  EXPECT_NEAR(work[Axis::Y], 0.0, 1e-9);  // the interpolator's sums, not the offsets
  EXPECT_NEAR(work[Axis::Z], 0.0, 1e-9);
  // The move ends at machine X 40: what is left of it, and nothing on the other axes.
  EXPECT_EQ(st.distance_to_go[Axis::X], 40.0 - st.servo.commanded[Axis::X]);
  EXPECT_GT(st.distance_to_go[Axis::X], 0.0);
  EXPECT_NEAR(st.distance_to_go[Axis::Y], 0.0, 1e-9);

  // After G92 X0 at work X 30 (machine 40): the shift is 30, work X counts from 0 again.
  ASSERT_TRUE(until_past(s, 7, 45.0));
  st = s.status();
  EXPECT_EQ(st.offsets.g92[Axis::X], 30.0);
  EXPECT_EQ(st.offsets.g5x[Axis::X], 10.0);
  work = work_position(st.servo.commanded, st.offsets);
  EXPECT_EQ(work[Axis::X], st.servo.commanded[Axis::X] - 10.0 - 30.0);
  EXPECT_EQ(st.distance_to_go[Axis::X], 55.0 - st.servo.commanded[Axis::X]);

  // At the end: no move left; the offsets the interpreter has after M2 (which selects G54).
  ASSERT_TRUE(s.idle());
  st = s.status();
  EXPECT_EQ(st.distance_to_go, Pose{});
  EXPECT_EQ(st.offsets.system, 1);
  EXPECT_EQ(st.offsets.g5x[Axis::X], 0.0);
}

TEST(WorkOffsetsScenario, TheToolLengthOffsetAndTheMdiSessionsOffsetsCarryOver) {
  Scenario s(control::test::mill());
  s.on(control::Mode::Mdi);
  s.must(Request::mdi("G21 G90 G10 L2 P1 X1 Y2 Z3"));
  ASSERT_TRUE(s.idle());
  s.must(Request::mdi("G54 G43.1 Z4"));  // a dynamic tool length offset
  ASSERT_TRUE(s.idle());
  s.must(Request::mdi("G0 X5"));  // a line that sets no offset: the session's stay
  ASSERT_TRUE(s.idle());
  const ControllerStatus st = s.status();
  EXPECT_EQ(st.offsets.system, 1);
  EXPECT_EQ(st.offsets.g5x[Axis::Z], 3.0);
  EXPECT_EQ(st.offsets.tool[Axis::Z], 4.0);
  EXPECT_EQ(st.servo.commanded[Axis::X], 6.0);
  const Pose work = work_position(st.servo.commanded, st.offsets);
  EXPECT_EQ(work[Axis::X], 5.0);
}

TEST(WorkOffsets, WorkPositionUndoesTheRotation) {
  WorkOffsets o;
  o.g5x[Axis::X] = 100;
  o.g92[Axis::X] = 1;
  o.xy_rotation_deg = 90;
  Pose machine;
  machine[Axis::X] = 100;  // work (x+1, y) rotated by 90°: (-y, x+1) → machine X = 100 - y
  machine[Axis::Y] = 6;    // = x + 1
  const Pose w = work_position(machine, o);
  EXPECT_NEAR(w[Axis::X], 5.0, 1e-12);
  EXPECT_NEAR(w[Axis::Y], 0.0, 1e-12);
  EXPECT_STREQ(work_system_name(9), "G59.3");
  EXPECT_STREQ(work_system_name(0), "");
}

}  // namespace
}  // namespace opencnc::controller::test
