// SPDX-License-Identifier: GPL-3.0-or-later
// Preflight: the extent and length of lines, arcs and helices (exact cases and seeded random
// arcs against dense sampling), the soft-limit check with file and line; program tails.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/canon/program_tail.hpp"
#include "opencnc/control/machine_action.hpp"
#include "opencnc/controller/preflight.hpp"

namespace opencnc::controller {
namespace {

constexpr double kPi = std::numbers::pi;

Pose xyz(double x, double y, double z = 0) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

/// An XY arc (helix when z changes) from the builder's position, centre (cx, cy), `turns` as the
/// canonical ARC_FEED gives them (sign = direction, |turns| − 1 extra circles).
void arc(canon::ProgramBuilder& b, canon::SegmentId id, double ex, double ey, double cx, double cy, int turns,
         double z) {
  canon::ArcFeed a;
  a.plane = canon::Plane::XY;
  a.first_end = ex;
  a.second_end = ey;
  a.first_center = cx;
  a.second_center = cy;
  a.rotation = turns;
  a.axis_end = z;
  a.end = xyz(ex, ey, z);
  b.arc_feed(id, a);
}

TEST(Preflight, QuarterArcReachesItsExtremeOnlyWhereTheSweepPasses) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"), xyz(10, 0));
  b.set_feed_rate(1000);
  arc(b, 0, 0, 10, 0, 0, 1, 0);   // counterclockwise from +X to +Y: passes no axis extreme
  arc(b, 1, 0, -10, 0, 0, 1, 0);  // on through −X to −Y: passes X = −10
  const canon::Program p = b.take();
  const Extent e0 = move_extent(p, 0), e1 = move_extent(p, 1);
  EXPECT_NEAR(e0.max[Axis::X], 10, 1e-12);
  EXPECT_NEAR(e0.max[Axis::Y], 10, 1e-12);
  EXPECT_NEAR(e0.min[Axis::X], 0, 1e-12);
  EXPECT_NEAR(e1.min[Axis::X], -10, 1e-12);
  EXPECT_NEAR(e1.min[Axis::Y], -10, 1e-12);
  EXPECT_NEAR(e1.max[Axis::Y], 10, 1e-12);
  EXPECT_NEAR(move_length(p, 0), 5 * kPi, 1e-9);
  EXPECT_NEAR(move_length(p, 1), 10 * kPi, 1e-9);
}

TEST(Preflight, HelixLengthAndFullCircles) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"), xyz(5, 0));
  b.set_feed_rate(1000);
  arc(b, 0, 5, 0, 0, 0, -3, -6);  // clockwise, end on start: three full turns, down 6 mm
  const canon::Program p = b.take();
  const Extent e = move_extent(p, 0);
  EXPECT_NEAR(e.min[Axis::X], -5, 1e-12);
  EXPECT_NEAR(e.max[Axis::Y], 5, 1e-12);
  EXPECT_NEAR(e.min[Axis::Z], -6, 1e-12);
  EXPECT_NEAR(move_length(p, 0), std::hypot(3 * 2 * kPi * 5, 6), 1e-9);
}

// Seeded random XY arcs (directions, turns, helices): the extent contains every point of the arc
// sampled densely from its own angles, and no more than the sampling's resolution beyond them.
TEST(Preflight, RandomArcExtentsMatchDenseSampling) {
  std::mt19937 rng(424242);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const double cx = 50 * u(rng), cy = 50 * u(rng), r = 0.5 + 20 * std::fabs(u(rng));
    const double a0 = kPi * u(rng), a1 = kPi * u(rng);
    const int turns = (u(rng) > 0 ? 1 : -1) * (1 + (trial % 3 == 0 ? 1 : 0));
    const Pose s = xyz(cx + r * std::cos(a0), cy + r * std::sin(a0), 0);
    canon::ProgramBuilder b(AxisMask::from_letters("XYZ"), s);
    b.set_feed_rate(1000);
    const double z = 5 * u(rng);
    arc(b, 0, cx + r * std::cos(a1), cy + r * std::sin(a1), cx, cy, turns, z);
    const canon::Program p = b.take();
    const Extent e = move_extent(p, 0);
    // The sweep as the angles say: counterclockwise for turns > 0.
    double sweep = a1 - a0;
    if (turns > 0) {
      while (sweep <= 0) sweep += 2 * kPi;
    } else {
      while (sweep >= 0) sweep -= 2 * kPi;
    }
    sweep += (turns > 0 ? 1 : -1) * 2 * kPi * (std::abs(turns) - 1);
    double lo_x = 1e9, hi_x = -1e9, lo_y = 1e9, hi_y = -1e9;
    for (int k = 0; k <= 20000; ++k) {
      const double a = a0 + sweep * k / 20000.0;
      lo_x = std::min(lo_x, cx + r * std::cos(a)), hi_x = std::max(hi_x, cx + r * std::cos(a));
      lo_y = std::min(lo_y, cy + r * std::sin(a)), hi_y = std::max(hi_y, cy + r * std::sin(a));
    }
    const double res = r * (1 - std::cos(std::fabs(sweep) / 20000.0)) + 1e-9;
    EXPECT_NEAR(e.max[Axis::X], hi_x, res) << trial;
    EXPECT_NEAR(e.min[Axis::X], lo_x, res) << trial;
    EXPECT_NEAR(e.max[Axis::Y], hi_y, res) << trial;
    EXPECT_NEAR(e.min[Axis::Y], lo_y, res) << trial;
    EXPECT_NEAR(e.min[Axis::Z], std::min(0.0, z), 1e-12) << trial;
    EXPECT_NEAR(move_length(p, 0), std::hypot(r * std::fabs(sweep), z), 1e-6 * (1 + r)) << trial;
  }
}

TEST(Preflight, SoftLimitErrorsNameTheLineAndTheAxis) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  canon::BlockOrigin o;
  o.line = 7;
  b.begin_block(o);
  b.set_feed_rate(1000);
  b.straight_feed(0, xyz(10, 0));
  o.line = 8;
  b.begin_block(o);
  arc(b, 1, 10, 20, 10, 10, 1, 0);  // counterclockwise around (10, 10): reaches X 20
  const canon::Program p = b.take();
  control::ServoConfig c;
  c.joint_count = 3;
  for (int j = 0; j < 3; ++j) {
    c.joints[static_cast<std::size_t>(j)].axis = static_cast<std::int8_t>(j);
    c.joints[static_cast<std::size_t>(j)].min_limit = -100;
    c.joints[static_cast<std::size_t>(j)].max_limit = 100;
  }
  Diagnostics d;
  EXPECT_TRUE(check_soft_limits(p, c, d));
  c.joints[0].max_limit = 19.5;
  EXPECT_FALSE(check_soft_limits(p, c, d));
  ASSERT_EQ(d.error_count(), 1u);
  EXPECT_EQ(d.items()[0].line, 8u);
  EXPECT_EQ(d.items()[0].code, "control.soft-limit");
  EXPECT_NE(d.items()[0].message.find("X to 20.0000"), std::string::npos) << d.items()[0].message;
  c.joints[0].wrapped = true;  // no limits
  Diagnostics none;
  EXPECT_TRUE(check_soft_limits(p, c, none));
}

TEST(ProgramTail, RestartsFromAPositionKeepingThePathSettings) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
  b.flood_on();
  b.set_feed_rate(600);
  b.straight_feed(0, xyz(10, 0));
  b.message("half way");
  b.set_feed_rate(1200);
  b.straight_feed(1, xyz(10, 10));
  b.straight_feed(2, xyz(0, 10));
  const canon::Program p = b.take();
  const auto t = canon::program_tail(p, 1, xyz(9, 1));
  ASSERT_EQ(t->size(), 2u);
  EXPECT_EQ(t->start(), xyz(9, 1));
  EXPECT_EQ(t->end(0), xyz(10, 10));
  EXPECT_EQ(t->end(1), xyz(0, 10));
  EXPECT_DOUBLE_EQ(t->feed(0), 1200);
  bool path_mode = false, flood = false, message = false;
  for (std::size_t i = 0; i < t->action_count(); ++i) {
    const canon::Action& a = t->action(i);
    path_mode = path_mode || a.kind == canon::ActionKind::MotionControl;
    flood = flood || a.kind == canon::ActionKind::FloodOn;
    if (a.kind == canon::ActionKind::Message) message = t->text(a.text) == "half way";
  }
  EXPECT_TRUE(path_mode);  // settings before the tail are kept
  EXPECT_FALSE(flood);     // what the machine already did is not done again
  EXPECT_TRUE(message);    // actions at the tail's start are kept
  const auto whole = canon::program_tail(p, 0, xyz(1, 1));
  EXPECT_EQ(whole->size(), 3u);
  EXPECT_EQ(whole->start_of(0), xyz(1, 1));
}

TEST(MachineActions, OnlyMarkerActionsBecomeRecords) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  b.set_spindle_speed(0, 2500);
  b.start_spindle_clockwise(0);
  b.comment("no record");
  b.set_motion_output_bit(3);
  b.wait_for_input(2, false, 0, 0);
  const canon::Program p = b.take();
  ASSERT_EQ(p.action_count(), 5u);
  EXPECT_EQ(control::machine_action(p, 0)->code, control::ActionCode::SpindleSpeed);
  EXPECT_EQ(control::machine_action(p, 0)->value, 2500);
  EXPECT_EQ(control::machine_action(p, 1)->code, control::ActionCode::SpindleCw);
  EXPECT_FALSE(control::machine_action(p, 2).has_value());
  EXPECT_EQ(control::machine_action(p, 3)->code, control::ActionCode::DigitalOutput);
  EXPECT_EQ(control::machine_action(p, 3)->index, 3);
  EXPECT_EQ(control::machine_action(p, 3)->index2, 1);
  EXPECT_EQ(control::machine_action(p, 4)->code, control::ActionCode::WaitInput);
  EXPECT_FALSE(control::machine_action(p, 4)->digital);
}

}  // namespace
}  // namespace opencnc::controller
