// SPDX-License-Identifier: GPL-3.0-or-later
// TraceChecker: finite differences, limit violations, contour error against lines and arcs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "opencnc/analysis/trace_checker.hpp"
#include "opencnc/canon/program_builder.hpp"

using namespace opencnc;

namespace {

Pose xy(double x, double y) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  return p;
}

canon::Program line_and_arc() {
  canon::ProgramBuilder b;
  b.set_feed_rate(600);
  b.straight_feed(0, xy(10, 0));
  canon::ArcFeed a;  // quarter circle about (10, 10), counterclockwise from (10, 0) to (20, 10)
  a.first_end = 20;
  a.second_end = 10;
  a.first_center = 10;
  a.second_center = 10;
  a.rotation = 1;
  a.end = xy(20, 10);
  b.arc_feed(1, a);
  return b.take();
}

}  // namespace

TEST(TraceChecker, FiniteDifferencesOfAConstantAcceleration) {
  const canon::Program p = line_and_arc();
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e6);
  analysis::TraceChecker c(p, limits, 1e-3);
  for (int n = 1; n <= 100; ++n) {
    const double t = n * 1e-3;
    c.add(xy(0.5 * 800 * t * t, 0), 0, 0);  // 800 mm/s² from rest: 8 mm in 0.1 s
  }
  const analysis::TraceReport& r = c.report();
  EXPECT_EQ(r.samples, 100u);
  EXPECT_NEAR(r.machining_time_s, 0.1, 1e-12);
  EXPECT_NEAR(r.axes[0].max_acceleration, 800, 1e-6);
  EXPECT_NEAR(r.axes[0].max_velocity, 800 * 0.1 - 0.4, 1e-6);  // backward difference at the last sample
  EXPECT_NEAR(r.path_length_mm, 4.0, 1e-9);
  // From rest the first samples see the acceleration switch on: a jerk of 800 / 2 ms.
  EXPECT_NEAR(r.axes[0].max_jerk, 400000, 1e-3);
  EXPECT_EQ(r.limit_violations, 0u);
  EXPECT_LE(r.max_contour_error_mm, 1e-12);
}

TEST(TraceChecker, CountsEverySampleAndAxisAboveALimit) {
  const canon::Program p = line_and_arc();
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);
  analysis::TraceChecker c(p, limits, 1e-3);
  c.add(xy(0.05, 0.05), 0, 0);  // 50 mm/s on X and Y, 50 000 mm/s² on both
  c.add(xy(0.10, 0.10), 0, 0);
  const analysis::TraceReport& r = c.report();
  EXPECT_EQ(r.limit_violations, 2u);  // acceleration of X and of Y in the first sample
  EXPECT_EQ(r.first_violation.axis, 0);
  EXPECT_EQ(r.first_violation.derivative, 2);
  EXPECT_NEAR(r.first_violation.value, 50000, 1e-6);
  EXPECT_NE(r.summary().find("2 limit violations"), std::string::npos);
}

// A trace that was already moving: its first two samples are the history, the one before them is
// unknown, so the first checked sample has no jerk; from the next one on the jerk is measured.
TEST(TraceChecker, AlreadyMovingTheFirstSampleHasNoJerkTheNextOnesHave) {
  const canon::Program p = line_and_arc();
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);
  analysis::TraceChecker c(p, limits, 1e-3);
  // x = J t³/6 with J = 9e4 from t = 0 (samples at 1 ms): a jerk-limited start.
  const auto x = [](int n) { return 9e4 * std::pow(n * 1e-3, 3) / 6; };
  c.start_moving(xy(x(1), 0), xy(x(0), 0));
  c.add(xy(x(2), 0), 0, 0);
  EXPECT_EQ(c.report().axes[0].max_jerk, 0.0);
  for (int n = 3; n <= 10; ++n) c.add(xy(x(n), 0), 0, 0);
  EXPECT_NEAR(c.report().axes[0].max_jerk, 9e4, 1e-3);
  EXPECT_NEAR(c.report().axes[0].max_acceleration, 9e4 * 9e-3, 1e-6);  // second difference at sample 10
  EXPECT_EQ(c.report().limit_violations, 0u);
  // A jerk above the limit after the first sample is counted: 50 nm more adds 5e4 mm/s³ (and
  // 50 mm/s², still within the acceleration limit).
  c.add(xy(x(11) + 5e-5, 0), 0, 0);
  EXPECT_EQ(c.report().limit_violations, 1u);
  EXPECT_EQ(c.report().first_violation.derivative, 3);
}

// The corner miss: a trace that turns round at a hairpin's end passes its end point; one that
// stays on the moves' middles (within 1 µm of both moves) misses it by half a move.
TEST(TraceChecker, ACornerCutOffShowsAsACornerMissNotAsAContourError) {
  canon::ProgramBuilder b;
  b.set_feed_rate(600);
  b.straight_feed(0, xy(1, 0));
  b.straight_feed(1, xy(0, 0.001));
  b.straight_feed(2, xy(1, 0.002));
  const canon::Program p = b.take();
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 1e6, 1e9);
  analysis::TraceChecker through(p, limits, 1e-3), cut(p, limits, 1e-3);
  // Along the moves, 0.01 mm a sample, to the ends and back (the segment ids of each move).
  for (int k = 1; k <= 300; ++k) {
    const int move = (k - 1) / 100;
    const double f = (k - 100 * move) / 100.0;
    const double x = move == 1 ? 1 - f : f, y = move == 0 ? 0.0 : 0.001 * (move - 1 + f);
    through.add(xy(x, y), static_cast<canon::SegmentId>(move), static_cast<canon::SegmentId>(move));
  }
  // From the middle of the first move on along x = 0.5 only: the end points are never visited.
  for (int k = 1; k <= 300; ++k) {
    const int move = (k - 1) / 100;
    cut.add(xy(std::min(0.5, k * 0.01), 0.001 * (k / 100.0)), static_cast<canon::SegmentId>(move),
            static_cast<canon::SegmentId>(move));
  }
  EXPECT_LE(through.report().max_corner_miss_mm, 1e-12);
  EXPECT_LE(cut.report().max_contour_error_mm, 0.0015);  // within the moves' spread
  EXPECT_NEAR(cut.report().max_corner_miss_mm, 0.5, 1e-3);
  EXPECT_EQ(cut.report().corner_miss_segment, 0u);
}

TEST(TraceChecker, ContourErrorIsTheDistanceToTheNearestProgrammedMove) {
  const canon::Program p = line_and_arc();
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 1e9, 1e12);
  analysis::TraceChecker c(p, limits, 1e-3);
  EXPECT_NEAR(c.distance_to_move(0, xy(5, 0.02)), 0.02, 1e-12);
  EXPECT_NEAR(c.distance_to_move(0, xy(-3, 4)), 5.0, 1e-12);  // beyond the start point
  const double s = std::sin(std::numbers::pi / 6), co = std::cos(std::numbers::pi / 6);
  EXPECT_NEAR(c.distance_to_move(1, xy(10 + 10.05 * s, 10 - 10.05 * co)), 0.05, 1e-9);
  EXPECT_NEAR(c.distance_to_move(1, xy(10, 10)), 10.0, 1e-9);  // the centre
  c.add(xy(5, 0.003), 0, 0);
  c.add(xy(10 + 9.99 * s, 10 - 9.99 * co), 1, 1);
  EXPECT_NEAR(c.report().max_contour_error_mm, 0.01, 1e-9);
}

namespace {

// The helix at a coarser pitch: from (10, 0, 0) about (5, 0), clockwise, `turns` turns
// down to Z = -depth (pitch depth / turns).
canon::Program helix(int turns, double depth) {
  canon::ProgramBuilder b;
  b.set_feed_rate(3000);
  b.straight_traverse(0, xy(10, 0));
  canon::ArcFeed a;
  a.first_end = 10;
  a.second_end = 0;
  a.first_center = 5;
  a.second_center = 0;
  a.rotation = -turns;
  a.axis_end = -depth;
  a.end = xy(10, 0);
  a.end[Axis::Z] = -depth;
  b.arc_feed(1, a);
  return b.take();
}

/// The helix at `turn` turns from its start (clockwise), radius 5 + `dr`, `dz` above it.
Pose on_helix(double turn, int turns, double depth, double dr = 0, double dz = 0) {
  const double angle = -2 * std::numbers::pi * turn;
  Pose p = xy(5 + (5 + dr) * std::cos(angle), (5 + dr) * std::sin(angle));
  p[Axis::Z] = -depth * turn / turns + dz;
  return p;
}

/// Nearest distance by brute force: the helix sampled every degree over every turn, then a
/// local refinement of the best sample (ternary search over ±1°).
double brute_force(int turns, double depth, const Pose& p) {
  auto dist = [&](double turn) {
    const Pose h = on_helix(turn, turns, depth);
    return std::sqrt(std::pow(h[0] - p[0], 2) + std::pow(h[1] - p[1], 2) + std::pow(h[2] - p[2], 2));
  };
  const int steps = 360 * turns;
  int best = 0;
  double best_d = dist(0);
  for (int i = 1; i <= steps; ++i) {
    const double d = dist(static_cast<double>(i) / 360);
    if (d < best_d) best_d = d, best = i;
  }
  double lo = std::max(0.0, (best - 1) / 360.0), hi = std::min<double>(turns, (best + 1) / 360.0);
  for (int it = 0; it < 200; ++it) {
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (dist(m1) < dist(m2))
      hi = m2;
    else
      lo = m1;
  }
  return std::min(best_d, dist(0.5 * (lo + hi)));
}

}  // namespace

// Issue 7: the contour check walked every turn of a helix for every sample (G2 ... P1000 did not
// finish). It now looks at the two turns next to the nearest one; the distances stay exact.
TEST(TraceChecker, AThousandTurnHelixIsCheckedCorrectly) {
  constexpr int kTurns = 1000;
  constexpr double kDepth = 100;  // pitch 0.1 mm
  const canon::Program p = helix(kTurns, kDepth);
  const auto limits = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 0);
  analysis::TraceChecker c(p, limits, 1e-3);
  // On the helix, at its ends and anywhere between: no error.
  for (double turn : {0.0, 0.25, 1.0, 137.6, 500.5, 999.0, 999.75, 1000.0}) {
    EXPECT_LT(c.distance_to_move(1, on_helix(turn, kTurns, kDepth)), 1e-9) << turn;
  }
  // Off it radially: the nearest point is at the same angle (a helix is symmetric about its normal
  // line there), whichever turn.
  for (double turn : {0.3, 1.5, 250.1, 777.7, 999.9}) {
    EXPECT_NEAR(c.distance_to_move(1, on_helix(turn, kTurns, kDepth, 0.02)), 0.02, 1e-9) << turn;
    EXPECT_NEAR(c.distance_to_move(1, on_helix(turn, kTurns, kDepth, -0.03)), 0.03, 1e-9) << turn;
  }
  // Between two turns, above the start and below the end: against a brute-force search.
  for (const Pose& q : {on_helix(500.2, kTurns, kDepth, 0.01, 0.05), on_helix(0, kTurns, kDepth, 0, 3),
                        on_helix(1000, kTurns, kDepth, 1, -2), xy(5, 0.5)}) {
    EXPECT_NEAR(c.distance_to_move(1, q), brute_force(kTurns, kDepth, q), 1e-7)
        << q[0] << " " << q[1] << " " << q[2];
  }
  // Through the report: samples along the whole helix, 0.01 mm off it at most.
  for (int k = 0; k <= 5000; ++k) {
    const double turn = kTurns * k / 5000.0;
    c.add(on_helix(turn, kTurns, kDepth, 0.01 * std::sin(k)), 1, 1);
  }
  EXPECT_LE(c.report().max_contour_error_mm, 0.01 + 1e-9);
  EXPECT_GT(c.report().max_contour_error_mm, 0.0099);
}
