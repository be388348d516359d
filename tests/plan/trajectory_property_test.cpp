// SPDX-License-Identifier: GPL-3.0-or-later
// Seeded random programs (lines from micrometres to centimetres, small and large arcs, helices,
// rapids, feed changes, dwells), random axis limits with and without jerk, random operator
// activity: the sampled trajectory never exceeds a limit and stays within the tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "opencnc/analysis/simulate.hpp"
#include "opencnc/canon/program_builder.hpp"

using namespace opencnc;

namespace {

struct Case {
  canon::Program program;
  plan::MachineLimits limits;
  double tolerance = 0;  ///< 0: the path is followed exactly (G61 / G61.1)
};

double log_uniform(std::mt19937& rng, double lo, double hi) {
  return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(rng));
}

Case random_case(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Case c;
  const bool jerk = seed % 2 == 1;
  c.limits.axes = AxisMask::from_letters("XYZ");
  for (int i = 0; i < 3; ++i) {
    c.limits.axis[static_cast<std::size_t>(i)] = {log_uniform(rng, 20, 200), log_uniform(rng, 200, 5000),
                                                  jerk ? log_uniform(rng, 2e4, 2e6) : 0.0};
  }
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"));
  const int mode = static_cast<int>(u(rng) * 4);
  if (mode == 0) {
    b.set_motion_control_mode(canon::MotionControl::ExactStop, 0);
  } else if (mode == 1) {
    b.set_motion_control_mode(canon::MotionControl::ExactPath, 0);
  } else {
    c.tolerance = log_uniform(rng, 0.001, 0.5);
    b.set_motion_control_mode(canon::MotionControl::Continuous, c.tolerance);
    b.set_naivecam_tolerance(mode == 3 ? c.tolerance * u(rng) : 0.0);
  }
  b.set_feed_rate(log_uniform(rng, 300, 12000));
  double x = 0, y = 0, z = 0, heading = 0;
  const int moves = 40 + static_cast<int>(u(rng) * 40);
  canon::SegmentId id = 0;
  for (int k = 0; k < moves; ++k) {
    const double r = u(rng);
    if (r < 0.05) b.set_feed_rate(log_uniform(rng, 300, 12000));
    if (r > 0.97) b.dwell(0.01);
    heading += (u(rng) - 0.5) * (u(rng) < 0.3 ? 3.0 : 0.6);
    if (r < 0.55) {  // line: from micrometres (dense CAM output) to centimetres
      const double len = log_uniform(rng, 0.001, 10);
      x += len * std::cos(heading);
      y += len * std::sin(heading);
      if (u(rng) < 0.2) z += (u(rng) - 0.5) * len;
      Pose e;
      e[Axis::X] = x;
      e[Axis::Y] = y;
      e[Axis::Z] = z;
      if (u(rng) < 0.08) {
        b.straight_traverse(id++, e);
      } else {
        b.straight_feed(id++, e);
      }
    } else {  // arc or helix in XY, tangent to the current heading or not
      const double radius = log_uniform(rng, 0.05, 20);
      const double sweep = log_uniform(rng, 0.05, 2 * std::numbers::pi);
      const int turn = u(rng) < 0.5 ? 1 : -1;
      const double nx = -std::sin(heading) * turn, ny = std::cos(heading) * turn;
      const double cx = x + radius * nx, cy = y + radius * ny;
      const double a1 = std::atan2(y - cy, x - cx) + turn * sweep;
      x = cx + radius * std::cos(a1);
      y = cy + radius * std::sin(a1);
      if (u(rng) < 0.3) z -= u(rng) * radius;
      canon::ArcFeed a;
      a.first_end = x;
      a.second_end = y;
      a.first_center = cx;
      a.second_center = cy;
      a.rotation = turn;
      a.axis_end = z;
      a.end[Axis::X] = x;
      a.end[Axis::Y] = y;
      a.end[Axis::Z] = z;
      b.arc_feed(id++, a);
      heading += turn * sweep;
    }
  }
  b.program_end();
  c.program = b.take();
  return c;
}

/// Feed override steps, rapid override, holds of random length: a few events per second.
analysis::SimulationOptions operator_activity(std::uint32_t seed) {
  analysis::SimulationOptions o;
  auto rng = std::make_shared<std::mt19937>(seed * 7919u);
  auto hold_until = std::make_shared<std::uint64_t>(0);
  auto feed = std::make_shared<double>(1.0);
  auto rapid = std::make_shared<double>(1.0);
  o.inputs = [=](std::uint64_t n, const traj::TickOutput&, traj::TickInput& in) {
    std::uniform_real_distribution<double> u(0, 1);
    if (u(*rng) < 0.004) *feed = u(*rng) * 2.0;
    if (u(*rng) < 0.002) *rapid = u(*rng);
    if (n > *hold_until && u(*rng) < 0.002) *hold_until = n + static_cast<std::uint64_t>(u(*rng) * 400);
    in.feed_override = *feed;
    in.rapid_override = *rapid;
    in.feed_hold = n < *hold_until;
    if (*feed < 0.05 && u(*rng) < 0.01) *feed = 1.0;  // do not crawl for ever
  };
  return o;
}

void expect_within_limits(const Case& c, const analysis::SimulationResult& r, std::uint32_t seed) {
  EXPECT_TRUE(r.finished) << "seed " << seed << ": " << r.report.summary();
  EXPECT_EQ(r.report.limit_violations, 0u) << "seed " << seed << ": " << r.report.summary();
  const double allowed = c.tolerance > 0 ? c.tolerance * (1 + 1e-9) + 1e-9 : 1e-7;
  EXPECT_LE(r.report.max_contour_error_mm, allowed) << "seed " << seed << ": " << r.report.summary();
  // And the other way: the path passes within the tolerance of every programmed end point. The
  // blends are sized to pass exactly at the tolerance, and between 1 ms samples the checker
  // takes the path as the arc through three of them: tight blends (a few µm, a few samples)
  // are resolved to about a tenth of the tolerance; a corner cut off by a blend sized only
  // against the moves (√2 at 90°, a hairpin skipped at its moves' middles) is far beyond that.
  EXPECT_LE(r.report.max_corner_miss_mm, 1.15 * allowed)
      << "seed " << seed << ", tolerance " << c.tolerance << ": " << r.report.summary();
}

}  // namespace

TEST(TrajectoryProperty, RandomProgramsStayWithinLimitsAndTolerance) {
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    const Case c = random_case(seed);
    analysis::SimulationOptions o;
    o.max_time_s = 3600;
    expect_within_limits(c, analysis::simulate(c.program, c.limits, o), seed);
  }
}

TEST(TrajectoryProperty, RandomOperatorActivityKeepsEveryLimit) {
  for (std::uint32_t seed = 101; seed <= 140; ++seed) {
    const Case c = random_case(seed);
    analysis::SimulationOptions o = operator_activity(seed);
    o.max_time_s = 3600;
    expect_within_limits(c, analysis::simulate(c.program, c.limits, o), seed);
  }
}
