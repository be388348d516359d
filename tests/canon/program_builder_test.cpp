// SPDX-License-Identifier: GPL-3.0-or-later
// ProgramBuilder: canonical (program units, work coordinates) → machine mm, as LinuxCNC's canon.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "opencnc/canon/program_builder.hpp"

using namespace opencnc;
using namespace opencnc::canon;

namespace {
Pose xyz(double x, double y, double z) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}
}  // namespace

TEST(ProgramBuilder, AppliesOffsetsRotationAndUnitsInLinuxCncOrder) {
  ProgramBuilder b;
  b.use_length_units(Units::Inch);
  b.set_g5x_offset(1, xyz(1, 0, 0));   // 25.4 mm
  b.set_g92_offset(xyz(0, 1, 0));      // 25.4 mm, applied before the rotation
  b.set_xy_rotation(90);
  b.use_tool_length_offset(xyz(0, 0, 0.5));
  b.straight_feed(0, xyz(1, 0, 0));
  const Program& p = b.program();
  ASSERT_EQ(p.size(), 1u);
  Pose e = p.end(0);
  // (1,0)+(0,1) = (1,1) inch, rotated 90° → (-1,1), + g5x (1,0) → (0,1) inch.
  EXPECT_NEAR(e[Axis::X], 0.0, 1e-12);
  EXPECT_NEAR(e[Axis::Y], 25.4, 1e-12);
  EXPECT_NEAR(e[Axis::Z], 12.7, 1e-12);
}

TEST(ProgramBuilder, OffsetsKeepTheirMillimetresWhenUnitsChange) {
  ProgramBuilder b;
  b.use_length_units(Units::Inch);
  b.set_g5x_offset(1, xyz(1, 0, 0));
  b.use_length_units(Units::Mm);
  b.straight_traverse(0, xyz(0, 0, 0));
  EXPECT_DOUBLE_EQ(b.program().end(0)[Axis::X], 25.4);
}

TEST(ProgramBuilder, ArcCentreLiesInThePlaneOfTheStartPoint) {
  ProgramBuilder b(kXyzabc, xyz(10, 0, 5));
  ArcFeed a;
  a.plane = Plane::XY;
  a.first_end = 0;
  a.second_end = 10;
  a.first_center = 0;
  a.second_center = 0;
  a.rotation = 1;
  a.axis_end = 0;  // helix down to z = 0
  a.end = xyz(0, 10, 0);
  b.set_feed_rate(100);
  b.arc_feed(0, a);
  const Program& p = b.program();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p.move(0).kind, MoveKind::Arc);
  const ArcGeometry& g = p.arc(0);
  EXPECT_DOUBLE_EQ(g.center[2], 5.0);
  EXPECT_DOUBLE_EQ(g.normal[2], 1.0);
  EXPECT_EQ(g.turns, 1);
  EXPECT_DOUBLE_EQ(p.feed(0), 100.0);
}

TEST(ProgramBuilder, ARigidTapEndsWhereItStarted) {
  ProgramBuilder b;
  b.straight_traverse(0, xyz(1, 2, 5));
  b.rigid_tap(1, xyz(1, 2, -10), 2.5);
  // Two moves of segment 1: in to the bottom, then back out to the start (kTapReturn), so that
  // every later move starts where the tap started; their feed is the way out's speed factor I.
  const Program& p = b.program();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p.move(1).kind, MoveKind::RigidTap);
  EXPECT_EQ(p.move(1).flags & kTapReturn, 0);
  EXPECT_EQ(p.end(1)[Axis::Z], -10.0);  // the bottom of the tap
  EXPECT_EQ(p.move(2).kind, MoveKind::RigidTap);
  EXPECT_NE(p.move(2).flags & kTapReturn, 0);
  EXPECT_EQ(p.end(2)[Axis::Z], 5.0);  // back at the start
  EXPECT_EQ(p.feed(1), 2.5);
  EXPECT_EQ(p.feed(2), 2.5);
  EXPECT_EQ(p.segment_of(2), 1u);
  EXPECT_EQ(p.moves_of(1), 2u);
  EXPECT_EQ(b.position()[Axis::Z], 5.0);           // the machine is back at the start
  // A helix after the tap has its centre in the plane of the real start point.
  ArcFeed a;
  a.first_end = 3, a.second_end = 2, a.first_center = 2, a.second_center = 2, a.rotation = 1, a.axis_end = 4;
  a.end = xyz(3, 2, 4);
  b.arc_feed(2, a);
  EXPECT_EQ(p.arc(3).center[2], 5.0);
  EXPECT_EQ(p.start_of(3)[Axis::Z], 5.0);
}

TEST(ProgramBuilder, UnderG96TheSpindleSpeedIsASurfaceSpeedAboutTheSpindleAxis) {
  ProgramBuilder b;
  Pose g5x{};
  g5x[Axis::X] = 12;
  b.set_g5x_offset(1, g5x);
  b.set_spindle_speed(0, 800);  // G97: rpm
  b.set_spindle_mode(0, 2000);  // G96 D2000
  b.set_spindle_speed(0, 150);  // S150: m/min
  Pose g92{};
  g92[Axis::X] = 3;
  b.set_g92_offset(g92);  // the spindle axis moves: the speed is given again
  b.use_length_units(Units::Inch);
  b.set_spindle_speed(0, 400);  // ft/min
  b.set_spindle_mode(0, 0);     // G97
  b.set_spindle_speed(0, 500);
  std::vector<Action> speeds;
  for (std::size_t k = 0; k < b.program().action_count(); ++k) {
    const Action& a = b.program().action(k);
    if (a.kind == ActionKind::SpindleSpeed) speeds.push_back(a);
  }
  ASSERT_EQ(speeds.size(), 5u);
  EXPECT_EQ(speeds[0].index2, 0);
  EXPECT_EQ(speeds[0].value, 800);
  EXPECT_EQ(speeds[1].index2, 1);
  EXPECT_EQ(speeds[1].value, 150000);  // mm/min
  EXPECT_EQ(b.program().action_pose(speeds[1].pose)[Axis::X], 12);
  EXPECT_EQ(speeds[2].value, 150000);
  EXPECT_EQ(b.program().action_pose(speeds[2].pose)[Axis::X], 15);
  EXPECT_DOUBLE_EQ(speeds[3].value, 400 * 304.8);
  EXPECT_EQ(speeds[4].index2, 0);
  EXPECT_EQ(speeds[4].value, 500);
}

TEST(ProgramBuilder, RotationTurnsTheNormalOfAnXzArc) {
  ProgramBuilder b;
  b.set_xy_rotation(90);
  ArcFeed a;
  a.plane = Plane::XZ;  // first = Z, second = X, normal = +Y
  a.first_end = 0;
  a.second_end = 2;
  a.first_center = 0;
  a.second_center = 1;
  a.rotation = -1;
  a.end = xyz(2, 0, 0);
  b.arc_feed(0, a);
  const ArcGeometry& g = b.program().arc(0);
  EXPECT_NEAR(g.normal[0], -1.0, 1e-12);  // +Y rotated by 90° about Z is -X
  EXPECT_NEAR(g.normal[1], 0.0, 1e-12);
  EXPECT_NEAR(g.center[1], 1.0, 1e-12);   // centre (x=1) rotated to y=1
}

TEST(ProgramBuilder, FeedsConvertToMillimetresExceptInverseTime) {
  ProgramBuilder b;
  b.use_length_units(Units::Inch);
  b.set_feed_rate(10);
  b.straight_feed(0, xyz(1, 0, 0));
  b.set_feed_mode(0, FeedMode::InverseTime);
  b.set_feed_rate(2);
  b.straight_feed(1, xyz(2, 0, 0));
  const Program& p = b.program();
  EXPECT_DOUBLE_EQ(p.feed(0), 254.0);
  EXPECT_DOUBLE_EQ(p.feed(1), 2.0);
  EXPECT_TRUE(p.move(1).flags & kInverseTime);
}

TEST(ProgramBuilder, ActionsKeepTheirPlaceBetweenMoves) {
  ProgramBuilder b;
  b.set_spindle_speed(0, 1000);
  b.start_spindle_clockwise(0);
  b.straight_traverse(0, xyz(1, 0, 0));
  b.dwell(0.5);
  b.straight_traverse(1, xyz(2, 0, 0));
  b.program_end();
  const Program& p = b.program();
  ASSERT_EQ(p.action_count(), 4u);
  EXPECT_EQ(p.action(0).kind, ActionKind::SpindleSpeed);
  EXPECT_EQ(p.action(0).before_move, 0u);
  EXPECT_EQ(p.action(2).kind, ActionKind::Dwell);
  EXPECT_EQ(p.action(2).before_move, 1u);
  EXPECT_EQ(p.action(3).before_move, 2u);
}

TEST(ProgramBuilder, StoresOnlyTheConfiguredAxes) {
  ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.straight_feed(0, xyz(1, 2, 3));
  EXPECT_EQ(b.program().stride(), 3);
  EXPECT_EQ(b.program().end(0), xyz(1, 2, 3));
}

TEST(ProgramBuilder, MillionMovesStayCompact) {
  ProgramBuilder b;
  b.set_feed_rate(1000);
  for (int i = 0; i < 1'000'000; ++i) b.straight_feed(static_cast<SegmentId>(i), xyz(i * 0.001, 0, 0));
  // 16-byte move + 6 doubles per pose: well under the 100 MB budget of a million-line program.
  EXPECT_LT(b.program().memory_bytes(), 70u * 1024 * 1024);
}

// `opencnc scan` measures each move once and has the builder start over: the program built
// after a restart is what an uninterrupted build would hold from there, minus the moves before.
TEST(ProgramBuilder, RestartDropsTheMovesAndKeepsTheConversion) {
  ProgramBuilder whole, restarted;
  for (ProgramBuilder* b : {&whole, &restarted}) {
    b->use_length_units(Units::Inch);
    b->set_g5x_offset(1, xyz(1, 0, 0));
    b->set_xy_rotation(90);
    b->set_feed_rate(10);
    b->straight_feed(0, xyz(1, 0, 0));
    b->straight_traverse(1, xyz(2, 1, 0));
  }
  const auto sources = restarted.program().sources_ptr();
  restarted.restart();
  EXPECT_TRUE(restarted.program().empty());
  EXPECT_EQ(restarted.program().sources_ptr(), sources);
  EXPECT_EQ(restarted.program().start(), whole.position());
  for (ProgramBuilder* b : {&whole, &restarted}) {
    b->straight_feed(2, xyz(3, 1, 1));  // the same feed: its index must be valid in the new table
    b->set_feed_rate(20);
    b->straight_feed(3, xyz(0, 0, 0));
  }
  const Program& w = whole.program();
  const Program& r = restarted.program();
  ASSERT_EQ(r.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(r.end(k), w.end(k + 2));
    EXPECT_DOUBLE_EQ(r.feed(k), w.feed(k + 2));
    EXPECT_EQ(r.segment_of(k), w.segment_of(k + 2));
  }
  EXPECT_EQ(r.start_of(0), w.start_of(2));
}
