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
