// SPDX-License-Identifier: GPL-3.0-or-later
// Arcs whose end lies off the start circle (within LinuxCNC's tolerance): the planner runs them
// as LinuxCNC does, along a spiral whose radius goes linearly with the angle. Its geometry, its
// trimming for blends, its limits in virtual time, the trace checker's contour error against
// it, and the arcs the planner still refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "opencnc/analysis/simulate.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "opencnc/plan/planner.hpp"
#include "opencnc/traj/path_eval.hpp"
#include "path_geometry.hpp"

using namespace opencnc;
using traj::BlockKind;
using traj::MotionBlock;

namespace {

const plan::MachineLimits kMill = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000);
const plan::MachineLimits kMillJerk =
    plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), 100, 1000, 1e5);

Pose xyz(double x, double y, double z = 0) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

/// The canonical program of a G-code text (millimetres, the standard modules).
canon::Program scan(const std::string& text) {
  gcode::Options o;
  o.user_units = canon::Units::Mm;
  o.extensions = gcode::standard_extensions(o.dialect);
  gcode::Interpreter interp(o);
  interp.open_text("spiral.ngc", text);
  canon::ProgramBuilder b(o.axes);
  b.program().set_sources(interp.sources());
  const gcode::RunStatus s = interp.run(b);
  EXPECT_EQ(s, gcode::RunStatus::Finished)
      << (interp.diagnostics().empty() ? "" : interp.diagnostics().items().back().format());
  return b.take();
}

canon::ArcGeometry xy_arc(double cx, double cy, int turns) {
  canon::ArcGeometry g;
  g.center[0] = cx;
  g.center[1] = cy;
  g.turns = turns;
  return g;
}

double length(const Pose& v) {
  double sum = 0;
  for (int i = 0; i < kAxisCount; ++i) sum += v[i] * v[i];
  return std::sqrt(sum);
}

double radius_at(const MotionBlock& b, double s, double cx, double cy) {
  const Pose p = traj::position_at(b, s);
  return std::hypot(p[Axis::X] - cx, p[Axis::Y] - cy);
}

}  // namespace

TEST(Spiral, AnArcEndingOffItsCircleBecomesASpiralThroughBothEnds) {
  // Start radius 5, end radius 5.02 (0.02 mm off: LinuxCNC accepts it), a quarter turn plus a
  // helix rise in Z.
  const Pose start = xyz(5, 0, 0), end = xyz(0, 5.02, -1);
  MotionBlock b;
  std::string why;
  ASSERT_TRUE(plan::detail::make_arc(start, end, xy_arc(0, 0, 1), b, why)) << why;
  ASSERT_EQ(b.kind, BlockKind::Spiral);
  const Pose e = traj::position_at(b, b.length);
  for (int i = 0; i < kAxisCount; ++i) EXPECT_NEAR(e[i], end[i], 1e-12) << i;
  // The radius goes linearly with the angle, the rise linearly too.
  for (double f : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double s = f * b.length;
    EXPECT_NEAR(radius_at(b, s, 0, 0), 5 + 0.02 * f, 1e-12) << f;
    EXPECT_NEAR(traj::position_at(b, s)[Axis::Z], -f, 1e-12) << f;
    const Pose p = traj::position_at(b, s);
    EXPECT_NEAR(std::atan2(p[Axis::Y], p[Axis::X]), f * std::numbers::pi / 2, 1e-12) << f;
  }
  // s is the spiral's length: |dp/ds| averages 1 and stays within the radius ratio of it.
  double sum = 0;
  const int n = 1000;
  for (int k = 0; k < n; ++k) {
    const double t = length(traj::tangent_at(b, (k + 0.5) * b.length / n));
    EXPECT_NEAR(t, 1.0, 0.005);
    sum += t;
  }
  EXPECT_NEAR(sum / n, 1.0, 1e-6);
}

TEST(Spiral, ClockwiseMultiTurnAndShrinkingSpiralsKeepTheirEnds) {
  struct Case {
    Pose start, end;
    canon::ArcGeometry arc;
  };
  const Case cases[] = {
      {xyz(10, 0), xyz(-9.99, 0), xy_arc(0, 0, -1)},      // half turn clockwise, shrinking
      {xyz(10, 0), xyz(0, -10.009, 3), xy_arc(0, 0, 3)},  // two extra turns, a helix
      {xyz(0.05, 0), xyz(0, 0.07), xy_arc(0, 0, 1)},      // small radius, 40 % larger at the end
      {xyz(3000, 0), xyz(-2997.5, 0), xy_arc(0, 0, 1)},   // large radius, 0.08 % smaller
  };
  for (const Case& c : cases) {
    MotionBlock b;
    std::string why;
    ASSERT_TRUE(plan::detail::make_arc(c.start, c.end, c.arc, b, why)) << why;
    EXPECT_EQ(b.kind, BlockKind::Spiral);
    const Pose e = traj::position_at(b, b.length);
    for (int i = 0; i < kAxisCount; ++i) EXPECT_NEAR(e[i], c.end[i], 1e-9 * (1 + std::fabs(c.end[i]))) << i;
    // Trimming the start (for a blend) keeps the rest of the curve exactly.
    MotionBlock t = b;
    const double d = 0.3 * b.length;
    plan::detail::trim_start(t, d);
    for (double f : {0.0, 0.4, 1.0}) {
      const Pose a = traj::position_at(t, f * t.length), want = traj::position_at(b, d + f * t.length);
      for (int i = 0; i < kAxisCount; ++i) EXPECT_NEAR(a[i], want[i], 1e-9 * (1 + std::fabs(want[i])));
    }
    // Points on the curve are at distance 0 from it; beside a flat one, at their offset.
    const double s = 0.61 * b.length;
    const Pose on = traj::position_at(b, s);
    EXPECT_NEAR(plan::detail::distance_to(b, on), 0.0, 1e-9);
    if (b.lin[Axis::Z] == 0) {
      Pose out = on;
      out[Axis::Z] += 0.5;  // off the plane: the nearest point is the one below
      EXPECT_NEAR(plan::detail::distance_to(b, out), 0.5, 1e-9);
    }
  }
}

TEST(Spiral, ArcsBeyondLinuxCncsToleranceAreStillRefused) {
  MotionBlock b;
  std::string why;
  // 0.1 mm off on a 5 mm radius: more than the absolute tolerance and 0.1 % of the radius.
  EXPECT_FALSE(plan::detail::make_arc(xyz(5, 0), xyz(0, 5.1), xy_arc(0, 0, 1), b, why));
  EXPECT_NE(why.find("off its circle"), std::string::npos) << why;
  // 8 mm off on a 6 m radius: within 0.1 % but beyond 100 times the absolute tolerance.
  EXPECT_FALSE(plan::detail::make_arc(xyz(6000, 0), xyz(0, 6008), xy_arc(0, 0, 1), b, why));
  // Through the planner: plan.bad-arc with the move's line.
  canon::ProgramBuilder builder;
  builder.set_feed_rate(100);
  canon::ArcFeed a;
  a.first_end = 0;
  a.second_end = 5.1;
  a.end = xyz(0, 5.1);
  a.first_center = -5;  // the builder's start is the origin: centre at (-5, 0)
  a.second_center = 0;
  a.rotation = 1;
  builder.arc_feed(0, a);
  canon::Program p = builder.take();
  plan::Planner planner(kMill);
  EXPECT_FALSE(planner.start(p));
  ASSERT_FALSE(planner.diagnostics().empty());
  EXPECT_EQ(planner.diagnostics().items()[0].code, "plan.bad-arc");
}

// What the interpreter accepts runs: every axis within its limits, the commanded path on the
// spiral (the trace checker measures against it), in the time its length asks.
TEST(Spiral, ProgramsWithOffCircleArcsRunWithinTheLimitsOnTheSpiral) {
  const std::string program =
      "G0 X5 Y0\n"
      "G3 X0 Y5.025 I-5 J0\n"         // 0.025 mm larger: within the absolute tolerance
      "G3 X-5.0 Y0 Z-1 I0 J-5.025\n"  // back to 5.0 with a rise
      "G2 X0 Y5 I5 J0 P2\n"           // a circle and a half, clockwise
      "G1 X0 Y300\n"
      "G2 X0 Y-299.75 I0 J-300 F3000\n"  // 0.25 mm smaller on a 300 mm radius (0.08 %)
      "M2\n";
  for (const char* mode : {"G61", "G64 P0.01"}) {
    const canon::Program p = scan(std::string("G21 G90 F1200 ") + mode + "\n" + program);
    // Three of the five arcs are spirals (the P2 circle and the one back to 5 mm are not).
    plan::Planner planner(kMill);
    ASSERT_TRUE(planner.start(p));
    auto q = std::make_unique<traj::BlockQueue>();
    int spirals = 0;
    while (planner.pump(*q) == plan::PlanStatus::Working || q->available() > 0) {
      for (std::size_t i = 0; i < q->available(); ++i) spirals += q->peek(i).kind == BlockKind::Spiral;
      q->pop(q->available());
      if (planner.pump(*q) != plan::PlanStatus::Working && q->available() == 0) break;
    }
    EXPECT_GE(spirals, 2) << mode;
    for (const plan::MachineLimits* limits : {&kMill, &kMillJerk}) {
      const analysis::SimulationResult r = analysis::simulate(p, *limits);
      EXPECT_TRUE(r.finished) << mode << r.report.summary();
      EXPECT_EQ(r.report.limit_violations, 0u) << mode << r.report.summary();
      const double tol = std::string(mode) == "G61" ? 1e-6 : 0.01 * (1 + 1e-9);
      EXPECT_LE(r.report.max_contour_error_mm, tol) << mode << r.report.summary();
    }
  }
}

TEST(Spiral, TheTraceCheckerMeasuresTheContourErrorAgainstTheSpiral) {
  const canon::Program p = scan("G21 G90 F600 G61\nG0 X10 Y0\nG3 X-10.02 Y0 I-10 J0\nM2\n");
  ASSERT_EQ(p.size(), 2u);
  analysis::TraceChecker on(p, kMill, 1e-3), circle(p, kMill, 1e-3);
  on.start_at(xyz(10, 0));
  circle.start_at(xyz(10, 0));
  // Samples on LinuxCNC's spiral (radius 10 → 10.02 linearly with the angle) against samples on
  // the start circle: the first measure nothing, the second up to the radius difference.
  for (int k = 0; k <= 200; ++k) {
    const double a = std::numbers::pi * k / 200, r = 10 + 0.02 * k / 200;
    on.add(xyz(r * std::cos(a), r * std::sin(a)), 1, 1);
    circle.add(xyz(10 * std::cos(a), 10 * std::sin(a)), 1, 1);
  }
  EXPECT_LE(on.report().max_contour_error_mm, 1e-9);
  EXPECT_NEAR(circle.report().max_contour_error_mm, 0.02, 1e-4);
}

TEST(Spiral, RandomOffCircleArcsKeepEveryLimit) {
  // Seeded: arcs of 0.2 to 40 mm radius, end radii off by what LinuxCNC accepts, random turns,
  // directions and rises, chained by lines, with and without jerk limits and blending.
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int run = 0; run < 8; ++run) {
    std::string g = run % 2 ? "G21 G90 G64 P0.02 F6000\nG0 X0 Y0\n" : "G21 G90 G61 F6000\nG0 X0 Y0\n";
    double x = 0, y = 0, z = 0;
    for (int k = 0; k < 10; ++k) {
      const double r = 0.2 + 40 * u01(rng) * u01(rng);
      const double angle = 2 * std::numbers::pi * u01(rng);
      const double cx = x + r * std::cos(angle), cy = y + r * std::sin(angle);
      const double sweep = 0.2 + 5.5 * u01(rng);
      const double off = (u01(rng) - 0.5) * 2 * std::max(0.0282, 0.00099 * r);
      const double r1 = r + off, a1 = angle + std::numbers::pi + (run % 3 == 0 ? -sweep : sweep);
      const double ex = cx + r1 * std::cos(a1), ey = cy + r1 * std::sin(a1), ez = z + (u01(rng) - 0.5) * 4;
      g += fmt::format("{} X{:.6f} Y{:.6f} Z{:.6f} I{:.6f} J{:.6f}\n", run % 3 == 0 ? "G2" : "G3", ex, ey, ez,
                       cx - x, cy - y);
      x = ex, y = ey, z = ez;
      x += 1;
      g += fmt::format("G1 X{:.6f}\n", x);
    }
    g += "M2\n";
    const canon::Program p = scan(g);
    const analysis::SimulationResult r = analysis::simulate(p, run % 4 < 2 ? kMill : kMillJerk);
    EXPECT_TRUE(r.finished) << run << r.report.summary();
    EXPECT_EQ(r.report.limit_violations, 0u) << run << r.report.summary();
    EXPECT_LE(r.report.max_contour_error_mm, run % 2 ? 0.02 * (1 + 1e-9) : 1e-6) << run << r.report.summary();
  }
}
