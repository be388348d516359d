// SPDX-License-Identifier: GPL-3.0-or-later
// Compensation: the seed's pitch table (0.0125 mm at 175 mm), tables per direction, backlash taken
// up within its velocity and acceleration limits, and seeded random reversals that never exceed
// them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "opencnc/core/axes.hpp"
#include "opencnc/machine/sim_switch.hpp"
#include "opencnc/motion/compensation.hpp"

namespace opencnc::motion {
namespace {

/// The X table of the drill retrofit paper: error (mm) every 50 mm from the origin.
PitchTable seed_table() {
  const double errors[] = {0,     0.003, 0.006, 0.010, 0.015, 0.018, 0.022,
                           0.027, 0.028, 0.030, 0.033, 0.037, 0.040};
  PitchTable t;
  t.count = 13;
  for (int i = 0; i < t.count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    t.position[k] = 50.0 * i;
    t.forward[k] = t.reverse[k] = errors[k];
  }
  return t;
}

CompensationConfig one_joint(const PitchTable& table, double backlash, double v, double a) {
  CompensationConfig c;
  c.period_s = 1e-3;
  c.joints[0].enabled = true;
  c.joints[0].pitch = table;
  c.joints[0].backlash = backlash;
  c.joints[0].max_velocity = v;
  c.joints[0].max_acceleration = a;
  return c;
}

TEST(PitchError, InterpolatesLinearlyAndHoldsTheEnds) {
  const PitchTable t = seed_table();
  int hint = 0;
  EXPECT_NEAR(pitch_error(t, 175.0, 1, hint), 0.0125, 1e-15);  // the paper's worked example
  EXPECT_NEAR(pitch_error(t, 50.0, 1, hint), 0.003, 1e-15);
  EXPECT_NEAR(pitch_error(t, 600.0, 1, hint), 0.040, 1e-15);
  EXPECT_NEAR(pitch_error(t, 700.0, -1, hint), 0.040, 1e-15);
  EXPECT_NEAR(pitch_error(t, -5.0, 1, hint), 0.0, 1e-15);
  // The hint only saves work: any hint gives the same value.
  for (int h : {-3, 0, 5, 11, 12, 400}) {
    int hh = h;
    EXPECT_EQ(pitch_error(t, 437.5, 1, hh), pitch_error(t, 437.5, 1, hint));
  }
}

TEST(PitchError, TablesPerDirection) {
  PitchTable t;
  t.count = 2;
  t.position = {0, 100};
  t.forward = {0, 0.010};
  t.reverse = {0.004, 0.020};
  int hint = 0;
  EXPECT_NEAR(pitch_error(t, 50, 1, hint), 0.005, 1e-15);
  EXPECT_NEAR(pitch_error(t, 50, -1, hint), 0.012, 1e-15);
  EXPECT_NEAR(pitch_error(t, 50, 0, hint), 0.0085, 1e-15);
}

/// Runs a joint along `path` (one commanded position per period) and checks the correction's
/// velocity and acceleration, by differences one period apart, against the limits plus what the
/// table's slope allows.
struct Trace {
  double max_v = 0, max_a = 0;
  std::vector<double> c;
};
Trace run(Compensation& comp, const std::vector<double>& path, bool homed, double offset = 0) {
  Trace r;
  double c1 = 0, c2 = 0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    const double c = comp.update(0, path[k], offset, homed);
    r.c.push_back(c);
    if (k >= 1) r.max_v = std::max(r.max_v, std::abs(c - c1) / 1e-3);
    if (k >= 2) r.max_a = std::max(r.max_a, std::abs(c - 2 * c1 + c2) / 1e-6);
    c2 = c1;
    c1 = c;
  }
  return r;
}

TEST(Compensation, CorrectsThePitchErrorOfTheSeedTable) {
  Compensation comp(one_joint(seed_table(), 0, 5, 200));
  // Approach 175 from below at 10 mm/s, homed all along: the correction is −E(175).
  std::vector<double> path;
  for (int k = 0; k <= 17500; ++k) path.push_back(0.01 * k);
  for (int k = 0; k < 200; ++k) path.push_back(175.0);
  const Trace r = run(comp, path, true);
  EXPECT_NEAR(r.c.back(), -0.0125, 1e-12);
  EXPECT_EQ(comp.direction(0), 1);
}

TEST(Compensation, TakesUpBacklashWithinItsLimits) {
  const double backlash = 0.02, v = 5, a = 200;
  Compensation comp(one_joint(PitchTable{}, backlash, v, a));
  std::vector<double> path;
  for (int k = 0; k <= 1000; ++k) path.push_back(0.05 * k);       // + at 50 mm/s
  for (int k = 1; k <= 1000; ++k) path.push_back(50 - 0.05 * k);  // reverse
  for (int k = 0; k < 100; ++k) path.push_back(0);                // rest
  const Trace r = run(comp, path, false);
  EXPECT_NEAR(r.c[1000], backlash / 2, 1e-12);  // taken up while moving +
  EXPECT_EQ(r.c.back(), -backlash / 2);         // and exactly the other way after the reversal
  EXPECT_LE(r.max_v, v * (1 + 1e-9));
  EXPECT_LE(r.max_a, a * (1 + 1e-9));
  // Time-optimal: 0.02 mm at 200 mm/s² without reaching 5 mm/s takes 2·√(0.02/200) = 20 ms; with
  // the speed changed by A·T each period and the position moved by the new speed, 19 periods.
  int settled = 0;
  for (std::size_t k = 1001; k < r.c.size(); ++k) {
    if (r.c[k] == -backlash / 2) {
      settled = static_cast<int>(k - 1000);
      break;
    }
  }
  EXPECT_GE(settled, 19);
  EXPECT_LE(settled, 21);
}

TEST(Compensation, SwitchingTheTableOnAtHomingIsSmooth) {
  Compensation comp(one_joint(seed_table(), 0, 5, 200));
  std::vector<double> path(50, 300.0);
  Trace before = run(comp, path, false);
  EXPECT_EQ(before.c.back(), 0.0);
  const Trace after = run(comp, path, true);
  EXPECT_NEAR(after.c.front(), 0.0, 200 * 1e-6 + 1e-15);  // one period's take-up: A·T²
  EXPECT_NEAR(after.c.back(), -0.022, 1e-12);
  EXPECT_LE(after.max_a, 200 * (1 + 1e-9));
}

TEST(Compensation, DirectionComesFromTheJointNotTheOffset) {
  Compensation comp(one_joint(PitchTable{}, 0.02, 5, 200));
  for (int k = 0; k < 100; ++k) comp.update(0, 0.1 * k, 0.0, false);
  EXPECT_EQ(comp.direction(0), 1);
  // Homing changes the offset by −30 while the joint keeps moving up: no reversal.
  comp.update(0, 10.0, -30.0, true);
  EXPECT_EQ(comp.direction(0), 1);
}

// An admin's new backlash while the joint stands: no step in the correction, the difference taken
// up within the new limits, the new half-backlash in the end.
TEST(Compensation, ANewBacklashAtRestIsTakenUpWithoutAStep) {
  Compensation comp(one_joint(PitchTable{}, 0.02, 5, 200));
  for (int k = 0; k < 100; ++k) comp.update(0, 0.1 * k, 0.0, false);
  for (int k = 0; k < 200; ++k) comp.update(0, 9.9, 0.0, false);
  ASSERT_EQ(comp.correction(0), 0.01);
  comp.set_backlash(0, 0.06, 2, 100);
  double last = comp.correction(0), fastest = 0;
  EXPECT_EQ(last, 0.01);
  for (int k = 0; k < 2000; ++k) {
    const double c = comp.update(0, 9.9, 0.0, false);
    fastest = std::max(fastest, std::abs(c - last) / 1e-3);
    last = c;
  }
  EXPECT_NEAR(last, 0.03, 1e-15);
  EXPECT_LE(fastest, 2 * (1 + 1e-9));
  EXPECT_EQ(comp.config().joints[0].backlash, 0.06);
}

// An admin's new pitch table while the joint stands homed at 175 mm: the correction does not step,
// moves to the new table's value within the take-up velocity, and the next motion reads the new
// table. The old table may change (the buffer is reused) only after the switch.
TEST(Compensation, ANewPitchTableAtRestIsTakenUpWithoutAStep) {
  Compensation comp(one_joint(seed_table(), 0, 2, 100));
  for (int k = 0; k <= 1750; ++k) comp.update(0, 0.1 * k, 0.0, true);
  for (int k = 0; k < 500; ++k) comp.update(0, 175, 0.0, true);
  ASSERT_NEAR(comp.correction(0), -0.0125, 1e-12);
  PitchTable doubled = seed_table();
  for (int i = 0; i < doubled.count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    doubled.forward[k] *= 2;
    doubled.reverse[k] *= 2;
  }
  comp.set_pitch_table(0, &doubled);
  EXPECT_EQ(&comp.pitch_table(0), &doubled);
  double last = comp.correction(0), fastest = 0;
  EXPECT_NEAR(last, -0.0125, 1e-12);
  for (int k = 0; k < 2000; ++k) {
    const double c = comp.update(0, 175, 0.0, true);
    fastest = std::max(fastest, std::abs(c - last) / 1e-3);
    last = c;
  }
  EXPECT_NEAR(last, -0.025, 1e-12);
  EXPECT_GT(fastest, 0.0);
  EXPECT_LE(fastest, 2 * (1 + 1e-9));
  comp.update(0, 175.1, 0.0, true);  // moving on: the new table, 0.020 at 150 mm and 0.030 at 200
  EXPECT_NEAR(comp.correction(0), -0.025 - 0.1 * (0.030 - 0.020) / 50, 1e-12);
}

TEST(Compensation, DisabledJointsGetNothing) {
  CompensationConfig c = one_joint(seed_table(), 0.02, 5, 200);
  c.joints[0].enabled = false;
  Compensation comp(c);
  EXPECT_EQ(comp.update(0, 175, 0, true), 0.0);
  EXPECT_EQ(comp.update(3, 175, 0, true), 0.0);
  EXPECT_EQ(comp.update(42, 175, 0, true), 0.0);
}

// Seeded random paths (speeds, reversals at random, the table switched on and off): the take-up
// never exceeds its limits and always comes to rest exactly on the target.
TEST(Compensation, RandomReversalsStayWithinTheLimits) {
  machine::SplitMix64 rng(2024);
  for (int trial = 0; trial < 300; ++trial) {
    const double backlash = 0.001 + 0.05 * (0.5 + 0.5 * rng.symmetric());
    const double v = 0.5 + 10 * (0.5 + 0.5 * rng.symmetric());
    const double a = 10 + 500 * (0.5 + 0.5 * rng.symmetric());
    Compensation comp(one_joint(PitchTable{}, backlash, v, a));
    std::vector<double> path;
    double x = 0, speed = 0;
    for (int k = 0; k < 3000; ++k) {
      if (rng.next() % 40 == 0) speed = 30 * rng.symmetric();  // new speed, often a reversal
      x += speed * 1e-3;
      path.push_back(x);
    }
    for (int k = 0; k < 300; ++k) path.push_back(x);
    const Trace r = run(comp, path, false);
    ASSERT_LE(r.max_v, v * (1 + 1e-9)) << trial;
    ASSERT_LE(r.max_a, a * (1 + 1e-9)) << trial;
    ASSERT_EQ(comp.pending(0), 0.0) << trial;
    ASSERT_EQ(std::abs(r.c.back()), backlash / 2) << trial;
  }
}

}  // namespace
}  // namespace opencnc::motion
