// SPDX-License-Identifier: GPL-3.0-or-later
// AxisMover: exact stops on a goal, never past it, acceleration (and with the average, jerk)
// within the limits — exact cases and seeded random goals, speeds and re-targeting.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "opencnc/control/axis_mover.hpp"

namespace opencnc::control {
namespace {

constexpr double kT = 1e-3;

/// Largest |first, second, third difference| / T^k of a sampled trajectory (from rest at p0).
struct Derivatives {
  double v = 0, a = 0, j = 0;
};
Derivatives derivatives(double p0, const std::vector<double>& x) {
  Derivatives d;
  double x1 = p0, x2 = p0, x3 = p0;
  for (double x0 : x) {
    d.v = std::max(d.v, std::fabs(x0 - x1) / kT);
    d.a = std::max(d.a, std::fabs(x0 - 2 * x1 + x2) / (kT * kT));
    d.j = std::max(d.j, std::fabs(x0 - 3 * x1 + 3 * x2 - x3) / (kT * kT * kT));
    x3 = x2, x2 = x1, x1 = x0;
  }
  return d;
}

std::vector<double> run_until_settled(AxisMover& m, int max = 200000) {
  std::vector<double> x;
  for (int i = 0; i < max && (x.empty() || !m.settled()); ++i) x.push_back(m.tick());
  return x;
}

TEST(AxisMover, MovesToTheGoalAndStopsThereExactly) {
  AxisMover m;
  m.configure(kT, 1000, 0, 5.0);
  m.move_to(105.0, 100);
  const auto x = run_until_settled(m);
  ASSERT_TRUE(m.settled());
  EXPECT_EQ(x.back(), 105.0);
  // Trapezoid: 0.1 s ramps and 0.9 s at 100 mm/s: 1.1 s, within a few periods.
  EXPECT_NEAR(static_cast<double>(x.size()) * kT, 1.1, 0.005);
  const Derivatives d = derivatives(5.0, x);
  EXPECT_LE(d.v, 100 * (1 + 1e-9));
  EXPECT_LE(d.a, 1000 * (1 + 1e-6));
  for (double p : x) EXPECT_LE(p, 105.0);
}

TEST(AxisMover, TinyMoveLandsInTwoPeriods) {
  AxisMover m;
  m.configure(kT, 1000, 0, 0.0);
  m.move_to(0.001, 100);
  const auto x = run_until_settled(m);
  EXPECT_EQ(x.back(), 0.001);
  EXPECT_LE(x.size(), 3u);
  EXPECT_LE(derivatives(0, x).a, 1000 * (1 + 1e-9));
}

TEST(AxisMover, RunsAtAVelocityAndStops) {
  AxisMover m;
  m.configure(kT, 500, 0, 0.0);
  m.run_at(-50);
  std::vector<double> x;
  for (int i = 0; i < 200; ++i) x.push_back(m.tick());
  EXPECT_DOUBLE_EQ(m.velocity(), -50);
  EXPECT_NEAR(m.stopping_distance(), 2.5, 1e-12);
  const double before = m.position();
  m.stop();
  const auto rest = run_until_settled(m);
  x.insert(x.end(), rest.begin(), rest.end());
  EXPECT_NEAR(before - x.back(), 2.5, 0.05);
  EXPECT_LE(derivatives(0, x).a, 500 * (1 + 1e-9));
}

TEST(AxisMover, MovingAverageLimitsJerkAndStillLandsExactly) {
  AxisMover m;
  m.configure(kT, 1000, 50000, 0.0);  // M = 40 periods
  EXPECT_EQ(m.filter_ticks(), 40);
  m.move_to(-20.0, 80);
  const auto x = run_until_settled(m);
  EXPECT_EQ(x.back(), -20.0);
  const Derivatives d = derivatives(0, x);
  EXPECT_LE(d.a, 1000 * (1 + 1e-6));
  EXPECT_LE(d.j, 50000 * (1 + 1e-6));
  for (double p : x) EXPECT_GE(p, -20.0 - 1e-12);  // the average of positions up to the goal
}

// Seeded random goals, speeds, limits and re-targeting while moving (also behind the motion):
// the last goal is reached exactly, never passed once it is set from rest, and the limits hold.
TEST(AxisMover, RandomGoalsAreReachedWithinTheLimits) {
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 400; ++trial) {
    const double a = 10 + 5000 * u(rng), speed = 1 + 200 * u(rng);
    const double jerk = trial % 3 == 0 ? a * (50 + 500 * u(rng)) : 0;
    AxisMover m;
    m.configure(kT, a, jerk, 100 * (u(rng) - 0.5));
    const double start = m.position();
    std::vector<double> x;
    double goal = start + 200 * (u(rng) - 0.5);
    m.move_to(goal, speed);
    const int retarget_at = trial % 2 == 0 ? static_cast<int>(300 * u(rng)) : -1;
    for (int i = 0; i < 400000 && (i <= retarget_at || !m.settled()); ++i) {
      if (i == retarget_at) {
        goal = m.position() + 50 * (u(rng) - 0.5);
        m.move_to(goal, speed);
      }
      x.push_back(m.tick());
    }
    ASSERT_TRUE(m.settled()) << trial;
    EXPECT_EQ(x.back(), goal) << trial;
    const Derivatives d = derivatives(start, x);
    EXPECT_LE(d.a, a * (1 + 1e-6)) << trial;
    if (jerk > 0) {
      EXPECT_LE(d.j, jerk * (1 + 1e-6)) << trial;
    }
    if (retarget_at < 0) {
      const double dir = goal > start ? 1.0 : -1.0;  // never past the goal (but for rounding)
      for (double p : x) EXPECT_LE(dir * (p - goal), 1e-12 * (1 + std::fabs(goal))) << trial;
    }
  }
}

}  // namespace
}  // namespace opencnc::control
