// SPDX-License-Identifier: GPL-3.0-or-later
// Planner: configuration and program errors, corners per path-control mode, G64 Q merging,
// markers, feed modes, arc geometry and per-axis caps, as seen in the published blocks.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "opencnc/analysis/reference_programs.hpp"
#include "opencnc/analysis/simulate.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/traj/path_eval.hpp"

using namespace opencnc;
using traj::BlockKind;
using traj::MarkerKind;
using traj::MotionBlock;

namespace {

const plan::MachineLimits kMillJerk =
    plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);
const plan::MachineLimits kMill = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);

Pose xyz(double x, double y, double z = 0) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

/// Plans the whole (small) program and returns the published blocks.
std::vector<MotionBlock> plan_all(const canon::Program& p, const plan::MachineLimits& limits = kMill,
                                  const plan::PlannerConfig& config = {}) {
  plan::Planner planner(limits, config);
  EXPECT_TRUE(planner.start(p)) << (planner.diagnostics().empty()
                                        ? ""
                                        : planner.diagnostics().items()[0].format());
  auto q = std::make_unique<traj::BlockQueue>();
  while (planner.pump(*q) == plan::PlanStatus::Working) {
  }
  std::vector<MotionBlock> out;
  for (std::size_t i = 0; i < q->available(); ++i) out.push_back(q->peek(i));
  return out;
}

std::vector<MotionBlock> path_blocks(const std::vector<MotionBlock>& all) {
  std::vector<MotionBlock> out;
  for (const MotionBlock& b : all) {
    if (b.kind != BlockKind::Marker) out.push_back(b);
  }
  return out;
}

std::string first_code(const plan::Planner& p) {
  return p.diagnostics().empty() ? std::string() : p.diagnostics().items()[0].code;
}

}  // namespace

TEST(Planner, RejectsLimitsThatAreNotPositive) {
  plan::MachineLimits bad = kMill;
  bad.axis[1].max_acceleration = -5;
  plan::Planner p(bad);
  EXPECT_FALSE(p.start(analysis::square_program(10, 600, {})));
  EXPECT_EQ(first_code(p), "plan.limits");
  EXPECT_NE(p.diagnostics().items()[0].message.find("axis Y"), std::string::npos);
  EXPECT_EQ(p.pump(*std::make_unique<traj::BlockQueue>()), plan::PlanStatus::Failed);

  plan::PlannerConfig config;
  config.normal_accel_share = 1.5;
  plan::Planner q(kMill, config);
  EXPECT_FALSE(q.start(analysis::square_program(10, 600, {})));
  EXPECT_EQ(first_code(q), "plan.config");
}

TEST(Planner, RejectsBadProgramsWithTheMovesLineAndPublishesNothing) {
  const auto check = [](auto build, const char* code, std::uint32_t line) {
    canon::ProgramBuilder b;
    canon::BlockOrigin o;
    o.line = line;
    b.begin_block(o);
    b.set_feed_rate(100);
    build(b);
    canon::Program p = b.take();
    plan::Planner planner(kMill);
    auto q = std::make_unique<traj::BlockQueue>();
    EXPECT_FALSE(planner.start(p));
    EXPECT_EQ(planner.pump(*q), plan::PlanStatus::Failed);
    EXPECT_EQ(q->available(), 0u);
    ASSERT_FALSE(planner.diagnostics().empty());
    EXPECT_EQ(first_code(planner), code);
    EXPECT_EQ(planner.diagnostics().items()[0].line, line);
  };
  check(
      [](canon::ProgramBuilder& b) {
        Pose e = xyz(1, 0);
        e[Axis::A] = 10;  // the machine has no A axis
        b.straight_feed(0, e);
      },
      "plan.axis-not-configured", 3);
  check(
      [](canon::ProgramBuilder& b) {
        b.set_feed_rate(0);
        b.straight_feed(0, xyz(1, 0));
      },
      "plan.feed-zero", 4);
  check([](canon::ProgramBuilder& b) { b.rigid_tap(0, xyz(0, 0, -5), 1.0); }, "plan.unsupported-move", 5);
  check(
      [](canon::ProgramBuilder& b) {
        canon::ArcFeed a;
        a.first_end = 10;
        a.end = xyz(10, 0);
        a.first_center = 0;  // centre on the start point
        b.arc_feed(0, a);
      },
      "plan.bad-arc", 6);
}

TEST(Planner, ExactStopCornersHaveZeroEntrySpeedAndNoBlends) {
  const auto blocks =
      path_blocks(plan_all(analysis::square_program(100, 6000, {canon::MotionControl::ExactStop})));
  ASSERT_EQ(blocks.size(), 4u);
  for (const MotionBlock& b : blocks) {
    EXPECT_EQ(b.kind, BlockKind::Line);
    EXPECT_EQ(b.v_entry, 0.0);
    EXPECT_DOUBLE_EQ(b.length, 100.0);
    EXPECT_DOUBLE_EQ(b.v_cap, 100.0);
    EXPECT_DOUBLE_EQ(b.accel, 1000.0);
  }
}

TEST(Planner, ContinuousCornersGetArcsWithinTheTolerance) {
  const double P = 0.01;
  const auto blocks =
      path_blocks(plan_all(analysis::square_program(100, 6000, {canon::MotionControl::Continuous, P})));
  ASSERT_EQ(blocks.size(), 7u);  // four lines, three corner arcs
  for (std::size_t i = 1; i < blocks.size(); i += 2) {
    const MotionBlock& arc = blocks[i];
    ASSERT_EQ(arc.kind, BlockKind::Arc);
    EXPECT_TRUE(arc.flags & traj::kBlend);
    // A 90° fillet: radius r with r·(1/cos 45° − 1) = P, so the middle of the arc is P from the
    // corner (as LinuxCNC sizes its blend arcs) and closer to both lines.
    const double r = 1.0 / std::fabs(arc.omega);
    EXPECT_NEAR(r * (1 / std::cos(std::numbers::pi / 4) - 1), P, 1e-12);
    // Centripetal acceleration at the cap within 95 % of the axis limit.
    EXPECT_NEAR(arc.v_cap * arc.v_cap / r, 0.95 * 1000, 1e-6);
    const Pose end = traj::position_at(arc, arc.length);
    const Pose next = blocks[i + 1].base;
    for (int k = 0; k < kAxisCount; ++k) EXPECT_EQ(end[k], next[k]);  // exactly continuous
  }
}

TEST(Planner, ExactPathStopsAtCornersButNotWhereMovesAreTangent) {
  canon::ProgramBuilder b;
  b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
  b.set_feed_rate(600);
  b.straight_feed(0, xyz(10, 0));
  b.straight_feed(1, xyz(20, 0));   // collinear: no stop
  b.straight_feed(2, xyz(20, 10));  // corner: stop
  const auto blocks = path_blocks(plan_all(b.take()));
  ASSERT_EQ(blocks.size(), 3u);
  EXPECT_GT(blocks[1].v_entry, 0.0);
  EXPECT_EQ(blocks[2].v_entry, 0.0);
}

TEST(Planner, NaiveCamToleranceMergesNearlyCollinearFeedLinesWithoutSmoothing) {
  plan::PlannerConfig merging;  // G64 Q's merge, where runs of short moves are not fitted
  merging.smooth_short_moves = false;
  const auto build = [](double q) {
    canon::ProgramBuilder b;
    b.set_motion_control_mode(canon::MotionControl::Continuous, 0.1);
    b.set_naivecam_tolerance(q);
    b.set_feed_rate(600);
    for (int i = 1; i <= 10; ++i)
      b.straight_feed(static_cast<canon::SegmentId>(i - 1), xyz(i, i % 2 ? 0.004 : 0));
    return b.take();
  };
  const auto merged = path_blocks(plan_all(build(0.01), kMill, merging));
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_EQ(merged[0].segment_first, 0u);
  EXPECT_EQ(merged[0].segment_last, 9u);
  // Unmerged: ten lines and nine small blends (just large enough for 2 × F10 mm/s).
  const auto separate = path_blocks(plan_all(build(0), kMill, merging));
  EXPECT_EQ(separate.size(), 19u);
  // Without jerk limits smoothing does not apply: the same blocks.
  EXPECT_EQ(path_blocks(plan_all(build(0))).size(), 19u);
  // With jerk limits the run is one fitted curve instead, within P/2 of the moves.
  const auto fitted = path_blocks(plan_all(build(0), kMillJerk));
  ASSERT_FALSE(fitted.empty());
  EXPECT_LT(fitted.size(), 10u);
  EXPECT_EQ(fitted.front().segment_first, 0u);
  EXPECT_EQ(fitted.back().segment_last, 9u);
}

TEST(Planner, RunsOfShortMovesBecomeOneCurvatureContinuousCurveWithinTheTolerance) {
  // 2000 moves of 0.05-0.2 mm on a spiral, coordinates rounded to 0.1 µm (CAM output): the fitted
  // spans join with the same point, tangent and curvature, run through at the feed's speed, and
  // stay within G64 P of the moves (the trace checker measures against the programmed moves).
  const canon::Program p = analysis::spiral_program(2000, 6000, {canon::MotionControl::Continuous, 0.01, 0});
  plan::Planner planner(kMillJerk, {});
  ASSERT_TRUE(planner.start(p));
  auto q = std::make_unique<traj::BlockQueue>();
  while (planner.pump(*q) == plan::PlanStatus::Working) {
  }
  EXPECT_GT(planner.stats().smoothed_runs, 0u);
  std::size_t curves = 0, joins = 0;
  for (std::size_t i = 1; i < q->available(); ++i) {
    const MotionBlock& a = q->peek(i - 1);
    const MotionBlock& b = q->peek(i);
    const bool spans = a.kind == BlockKind::Bezier && b.kind == BlockKind::Bezier;
    if (!spans || (a.flags & traj::kBlend) || (b.flags & traj::kBlend)) continue;  // fitted spans only
    ++joins;
    const Pose ta = traj::tangent_at(a, a.length), tb = traj::tangent_at(b, 0);
    const Pose ka = traj::curvature_at(a, a.length), kb = traj::curvature_at(b, 0);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(ta[k], tb[k], 1e-9) << i;
      EXPECT_NEAR(ka[k], kb[k], 1e-6) << i;
    }
  }
  for (std::size_t i = 0; i < q->available(); ++i) curves += q->peek(i).kind == BlockKind::Bezier;
  EXPECT_GT(curves, 20u);
  EXPECT_GT(joins, 20u);
  analysis::SimulationOptions unfitted;
  unfitted.planner.smooth_short_moves = false;
  const analysis::SimulationResult r = analysis::simulate(p, kMillJerk);
  const analysis::SimulationResult lines = analysis::simulate(p, kMillJerk, unfitted);
  EXPECT_EQ(r.report.limit_violations, 0u) << r.report.summary();
  EXPECT_LE(r.report.max_contour_error_mm, 0.01) << r.report.summary();
  // Faster than the same moves with their blends, and close to the feed (path / 100 mm/s, the
  // start and the stop included).
  EXPECT_LT(r.motion_time_s, 0.8 * lines.motion_time_s) << r.report.summary();
  EXPECT_LE(r.motion_time_s, 1.1 * r.report.path_length_mm / 100.0) << r.report.summary();
}

TEST(Planner, ActionsBecomeMarkersInProgramOrder) {
  canon::ProgramBuilder b;
  b.set_feed_rate(600);
  b.straight_feed(0, xyz(1, 0));
  b.flood_on();
  b.dwell(0.5);
  b.straight_feed(1, xyz(2, 0));
  b.change_tool(3);
  b.start_spindle_clockwise(0);
  b.straight_feed(2, xyz(3, 0));
  b.program_stop();
  b.optional_program_stop();
  b.program_end();
  const auto blocks = plan_all(b.take());
  std::vector<MarkerKind> markers;
  for (const MotionBlock& m : blocks) {
    if (m.kind == BlockKind::Marker) markers.push_back(m.marker);
  }
  const std::vector<MarkerKind> expected = {
      MarkerKind::Report,      MarkerKind::Dwell,       MarkerKind::Sync,         MarkerKind::Report,
      MarkerKind::SpindleWait, MarkerKind::ProgramStop, MarkerKind::OptionalStop, MarkerKind::ProgramEnd};
  EXPECT_EQ(markers, expected);
  for (const MotionBlock& m : blocks) {
    if (m.kind == BlockKind::Marker && m.marker == MarkerKind::Dwell) {
      EXPECT_EQ(m.value, 0.5);
      EXPECT_EQ(m.v_entry, 0.0);
      EXPECT_EQ(m.base[0], 1.0);
    }
  }
}

TEST(Planner, FeedModesGiveTheNominalSpeedAlongThePath) {
  canon::ProgramBuilder b;
  b.set_motion_control_mode(canon::MotionControl::ExactStop, 0);
  b.set_feed_rate(600);  // 10 mm/s
  b.straight_feed(0, xyz(10, 0));
  b.set_feed_mode(0, canon::FeedMode::InverseTime);
  b.set_feed_rate(30);  // 2 s for the move
  b.straight_feed(1, xyz(10, 10));
  b.set_feed_mode(0, canon::FeedMode::UnitsPerMinute);
  b.set_feed_rate(600);
  Pose e = xyz(10, 20);
  e[Axis::C] = 90;  // rotary motion along: feed applies to XYZ
  b.straight_feed(2, e);
  e[Axis::X] = 30;
  e[Axis::Y] = 0;
  b.straight_traverse(3, e);
  plan::MachineLimits lim = plan::MachineLimits::uniform(AxisMask::from_letters("XYZC"), 100, 1000);
  const auto blocks = path_blocks(plan_all(b.take(), lim, {}));
  std::vector<MotionBlock> lines;
  for (const MotionBlock& m : blocks) {
    if (!(m.flags & traj::kBlend)) lines.push_back(m);
  }
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_DOUBLE_EQ(lines[0].feed, 10.0);
  EXPECT_NEAR(lines[1].feed * 2.0, 10.0, 1e-9);  // 10 mm in 2 s
  // s runs over √(10² + 90²); the XYZ part moves at 10 mm/s.
  EXPECT_NEAR(lines[2].feed / std::hypot(10.0, 90.0) * 10.0, 10.0, 1e-9);
  EXPECT_EQ(lines[3].feed_class, traj::FeedClass::Rapid);
  // A rapid along (20, −20): both axes at 100 mm/s, so √2 · 100 along s.
  EXPECT_NEAR(lines[3].feed, 100 * std::sqrt(2.0), 1e-9);
}

TEST(Planner, ArcsAndHelicesEndExactlyWhereProgrammed) {
  canon::ProgramBuilder b(kXyzabc, xyz(10, 0, 0));
  b.set_motion_control_mode(canon::MotionControl::ExactStop, 0);
  b.set_feed_rate(600);
  canon::ArcFeed full;  // a whole circle: start and end coincide
  full.first_end = 10;
  full.second_end = 0;
  full.end = xyz(10, 0, 0);
  full.rotation = 1;
  b.arc_feed(0, full);
  canon::ArcFeed helix;  // two turns down 4 mm, clockwise
  helix.first_end = 0;
  helix.second_end = 10;
  helix.axis_end = -4;
  helix.end = xyz(0, 10, -4);
  helix.rotation = -2;
  b.arc_feed(1, helix);
  const auto blocks = path_blocks(plan_all(b.take()));
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_NEAR(blocks[0].length, 2 * std::numbers::pi * 10, 1e-9);
  const MotionBlock& h = blocks.back();
  const Pose end = traj::position_at(h, h.length);
  EXPECT_NEAR(end[0], 0, 1e-9);
  EXPECT_NEAR(end[1], 10, 1e-9);
  EXPECT_NEAR(end[2], -4, 1e-9);
  EXPECT_LT(h.omega, 0);  // clockwise
}

TEST(Planner, ARigidTapIsAPairOfSpindleSynchronisedBlocksEnteredAndLeftAtRest) {
  canon::ProgramBuilder b;
  b.set_feed_rate(600);
  b.straight_feed(0, xyz(0, 0, 2));
  b.start_speed_feed_synch(0, 1.25, false);
  b.rigid_tap(1, xyz(0, 0, -8), 1.5);
  b.stop_speed_feed_synch();
  b.straight_feed(2, xyz(4, 0, 2));
  const auto blocks = path_blocks(plan_all(b.take()));
  ASSERT_EQ(blocks.size(), 4u);
  const MotionBlock& in = blocks[1];
  const MotionBlock& out = blocks[2];
  EXPECT_TRUE(in.flags & traj::kRigidTap);
  EXPECT_FALSE(in.flags & traj::kTapReturn);
  EXPECT_TRUE(out.flags & traj::kRigidTap);
  EXPECT_TRUE(out.flags & traj::kTapReturn);
  for (const MotionBlock* t : {&in, &out}) {
    EXPECT_EQ(t->feed_class, traj::FeedClass::SpindleSync);
    EXPECT_DOUBLE_EQ(t->feed, 1.25);  // mm per revolution along the line
    EXPECT_DOUBLE_EQ(t->tap_scale, 1.5);
    EXPECT_DOUBLE_EQ(t->length, 10.0);
    EXPECT_EQ(t->v_entry, 0.0);
    EXPECT_EQ(t->flags & traj::kFeedHoldAllowed, 0);
  }
  EXPECT_EQ(blocks[3].v_entry, 0.0);
  // The way out ends where the tap started, where the next block begins.
  const Pose back = traj::position_at(out, out.length);
  EXPECT_NEAR(back[Axis::Z], 2.0, 1e-12);
  EXPECT_EQ(blocks[3].base[Axis::Z], back[Axis::Z]);
}
