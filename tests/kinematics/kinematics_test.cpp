// SPDX-License-Identifier: GPL-3.0-or-later
// Five-axis kinematics: seeded round trips over random poses on every structure, the tool tip held
// on one point while the rotary axes sweep (ISO 10791-6's RTCP check), the Jacobian against finite
// differences, singular and unreachable tool axes, and the configuration's checks.
#include "opencnc/kinematics/kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

using namespace opencnc;
using namespace opencnc::kinematics;

namespace {

struct Machine {
  std::string name;
  Config config;
  /// The range the random poses take the rotary joints over (degrees), first and second axis.
  double range0;
  double range1;
};

RotaryAxis axis(Axis joint, Vec3 direction, Vec3 pivot) {
  return RotaryAxis{joint, direction, pivot};
}

Config make(Structure s, RotaryAxis first, RotaryAxis second) {
  Config c{s, {first, second}};
  EXPECT_EQ(prepare(c), ConfigError::Ok);
  return c;
}

/// Every structure, with pivots off the origin and off each other (a real trunnion's C axis does
/// not meet its A axis to the micrometre).
std::vector<Machine> machines() {
  return {
      {"A/C trunnion",
       make(Structure::TableTable, axis(Axis::A, {1, 0, 0}, {0, 12.5, -80}),
            axis(Axis::C, {0, 0, 1}, {3.2, 11.9, 0})),
       110, 720},
      {"B/C trunnion",
       make(Structure::TableTable, axis(Axis::B, {0, 1, 0}, {-40, 0, -120}),
            axis(Axis::C, {0, 0, 1}, {-39.5, 0.4, 0})),
       110, 720},
      {"B/C head",
       make(Structure::HeadHead, axis(Axis::C, {0, 0, 1}, {0.3, -0.2, 0}),
            axis(Axis::B, {0, 1, 0}, {0, 0.1, 150})),
       720, 110},
      {"A/C head",
       make(Structure::HeadHead, axis(Axis::C, {0, 0, 1}, {0, 0, 0}), axis(Axis::A, {1, 0, 0}, {0, 0, 210})),
       720, 110},
      {"B head, C table",
       make(Structure::HeadTable, axis(Axis::B, {0, 1, 0}, {0, 0, 120}),
            axis(Axis::C, {0, 0, 1}, {250, 180, 0})),
       110, 720},
      {"nutating B/C head",
       make(Structure::HeadHead, axis(Axis::C, {0, 0, 1}, {0, 0, 0}), axis(Axis::B, {0, 1, 1}, {0, 30, 160})),
       720, 360},
  };
}

Pose random_pose(std::mt19937_64& rng, const Machine& m) {
  std::uniform_real_distribution<double> linear(-500, 500);
  std::uniform_real_distribution<double> r0(-m.range0 / 2, m.range0 / 2);
  std::uniform_real_distribution<double> r1(-m.range1 / 2, m.range1 / 2);
  Pose j{};
  for (int a = 0; a < 3; ++a) j[a] = linear(rng);
  j[index(m.config.rotary[0].joint)] = r0(rng);
  j[index(m.config.rotary[1].joint)] = r1(rng);
  return j;
}

double distance(const Vec3& a, const Vec3& b) {
  return norm(a - b);
}

double joint_distance(const Pose& a, const Pose& b) {
  double d = 0;
  for (int i = 0; i < kAxisCount; ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

}  // namespace

// Inverse then forward returns the tool, and the branch nearest the pose it started from is the
// pose itself, over random poses of every structure (issue 25: ≤ 1e-9 mm).
TEST(Kinematics, RandomPosesRoundTripWithinANanometre) {
  std::mt19937_64 rng(25);
  std::uniform_real_distribution<double> nudge(-0.5, 0.5);
  std::uniform_real_distribution<double> length(0, 250);
  for (const Machine& m : machines()) {
    double worst_tip = 0;
    double worst_axis = 0;
    double worst_joint = 0;
    double worst_branch = 0;
    int singular = 0;
    for (int n = 0; n < 20000; ++n) {
      const Pose j = random_pose(rng, m);
      const double tool = length(rng);
      const ToolPose t = forward(m.config, j, tool);
      ASSERT_NEAR(norm(t.axis), 1.0, 1e-12) << m.name;
      Pose from = j;  // where the machine stood a moment before: a little off in every rotary joint
      from[index(m.config.rotary[0].joint)] += nudge(rng);
      from[index(m.config.rotary[1].joint)] += nudge(rng);
      const Solutions all = inverse_all(m.config, t, tool, from);
      ASSERT_NE(all.status, Solve::Unreachable) << m.name;
      for (int s = 0; s < all.count; ++s) {
        const ToolPose back = forward(m.config, all.joints[static_cast<std::size_t>(s)], tool);
        worst_tip = std::max(worst_tip, distance(back.tip_mm, t.tip_mm));
        worst_axis = std::max(worst_axis, distance(back.axis, t.axis));
      }
      // The pose itself is one of the solutions, and the one taken unless the other branch lies
      // as near the start (the two meet where the tool's axis grazes the edge of what a nutating
      // head reaches).
      double nearest = 1e9;
      double other_branch = 1e9;
      for (int s = 0; s < all.count; ++s) {
        const double d = joint_distance(all.joints[static_cast<std::size_t>(s)], j);
        nearest = std::min(nearest, d);
        if (d > 1e-6) other_branch = std::min(other_branch, d);
      }
      worst_joint = std::max(worst_joint, nearest);
      const Inverse best = inverse(m.config, t, tool, from);
      if (best.status == Solve::Singular) ++singular;
      if (other_branch > 4) worst_branch = std::max(worst_branch, joint_distance(best.joints, j));
    }
    EXPECT_LE(worst_tip, 1e-9) << m.name;
    EXPECT_LE(worst_axis, 1e-10) << m.name;
    // Joints to 1e-7 (mm, degrees): near the edge of a nutating head's reach the angles are
    // ill-conditioned in the tool's axis; the tip, which is what the round trip must keep, is not.
    EXPECT_LE(worst_joint, 1e-7) << m.name << " (the pose itself is a solution)";
    EXPECT_LE(worst_branch, 1e-7) << m.name << " (the branch nearest the start is the pose itself)";
    EXPECT_EQ(singular, 0) << m.name;
  }
}

// ISO 10791-6's RTCP check: the tip held on one point while the rotary axes sweep their ranges.
// Each commanded joint pose puts the tip back on the point.
TEST(Kinematics, TheTipStaysOnItsPointWhileTheRotaryAxesSweep) {
  for (const Machine& m : machines()) {
    const Vec3 point{35, -20, 15};
    const double tool = 120;
    Pose from{};
    double worst = 0;
    double worst_axis = 0;
    for (int k = 0; k <= 720; ++k) {
      // The tool's axis tilted from 0 to 60° and back while it turns twice around Z.
      const double tilt = 60.0 * std::sin(k * std::numbers::pi / 720) * std::numbers::pi / 180;
      const double turn = k * std::numbers::pi / 180;
      const ToolPose want{point,
                          {std::sin(tilt) * std::cos(turn), std::sin(tilt) * std::sin(turn), std::cos(tilt)}};
      const Inverse j = inverse(m.config, want, tool, from);
      if (m.name.starts_with("nutating") && j.status == Solve::Unreachable) continue;
      ASSERT_NE(j.status, Solve::Unreachable) << m.name << " at step " << k;
      const ToolPose got = forward(m.config, j.joints, tool);
      worst = std::max(worst, distance(got.tip_mm, point));
      worst_axis = std::max(worst_axis, distance(got.axis, want.axis));
      // The rotary joints follow the sweep without a jump of half a turn (a flip at feed).
      if (k > 1) {
        EXPECT_LT(std::abs(j.joints[index(m.config.rotary[0].joint)] - from[index(m.config.rotary[0].joint)]),
                  10)
            << m.name << " at step " << k;
        EXPECT_LT(std::abs(j.joints[index(m.config.rotary[1].joint)] - from[index(m.config.rotary[1].joint)]),
                  10)
            << m.name << " at step " << k;
      }
      from = j.joints;
    }
    EXPECT_LE(worst, 1e-9) << m.name;
    EXPECT_LE(worst_axis, 1e-12) << m.name;
  }
}

// The Jacobian agrees with central differences of `forward` on every structure.
TEST(Kinematics, TheJacobianIsTheDerivativeOfForward) {
  std::mt19937_64 rng(2510);
  for (const Machine& m : machines()) {
    for (int n = 0; n < 200; ++n) {
      const Pose j = random_pose(rng, m);
      const double tool = 90;
      const Jacobian jac = jacobian(m.config, j, tool);
      const std::array<Axis, 5> joints{Axis::X, Axis::Y, Axis::Z, m.config.rotary[0].joint,
                                       m.config.rotary[1].joint};
      for (std::size_t col = 0; col < 5; ++col) {
        const double h = 1e-5;
        Pose plus = j;
        Pose minus = j;
        plus[index(joints[col])] += h;
        minus[index(joints[col])] -= h;
        const ToolPose a = forward(m.config, plus, tool);
        const ToolPose b = forward(m.config, minus, tool);
        for (int r = 0; r < 3; ++r) {
          EXPECT_NEAR(jac[static_cast<std::size_t>(r)][col], (a.tip_mm[r] - b.tip_mm[r]) / (2 * h), 1e-5)
              << m.name << " tip row " << r << " column " << col;
          EXPECT_NEAR(jac[static_cast<std::size_t>(r + 3)][col], (a.axis[r] - b.axis[r]) / (2 * h), 1e-7)
              << m.name << " axis row " << r << " column " << col;
        }
      }
    }
  }
}

// Two branches of one tool axis: the one with the least rotary motion is taken (A tilted either
// way with C half a turn apart on a trunnion).
TEST(Kinematics, TheBranchWithTheLeastRotaryMotionIsChosen) {
  const Config c = machines()[0].config;  // A/C trunnion
  Pose j{};
  j[index(Axis::A)] = 30;
  j[index(Axis::C)] = 40;
  const ToolPose t = forward(c, j, 100);
  const Solutions all = inverse_all(c, t, 100, j);
  ASSERT_EQ(all.count, 2);
  const double a0 = all.joints[0][index(Axis::A)];
  const double a1 = all.joints[1][index(Axis::A)];
  EXPECT_NEAR(std::abs(a0), 30, 1e-9);
  EXPECT_NEAR(a0, -a1, 1e-9);
  EXPECT_NEAR(std::abs(all.joints[0][index(Axis::C)] - all.joints[1][index(Axis::C)]), 180, 1e-9);
  Pose near_other = j;
  near_other[index(Axis::A)] = -25;
  near_other[index(Axis::C)] = 215;
  const Inverse other = inverse(c, t, 100, near_other);
  EXPECT_NEAR(other.joints[index(Axis::A)], -30, 1e-9);
  EXPECT_NEAR(other.joints[index(Axis::C)], 220, 1e-9);
  const Inverse same = inverse(c, t, 100, j);
  EXPECT_NEAR(same.joints[index(Axis::A)], 30, 1e-9);
  EXPECT_NEAR(same.joints[index(Axis::C)], 40, 1e-9);
}

// Whole turns are settled nearest the start: C at 715° stays there, not at −5°.
TEST(Kinematics, AngleTurnsAreTakenNearestTheStart) {
  const Config c = machines()[0].config;
  Pose j{};
  j[index(Axis::A)] = 20;
  j[index(Axis::C)] = 715;
  const ToolPose t = forward(c, j, 50);
  const Inverse back = inverse(c, t, 50, j);
  EXPECT_NEAR(back.joints[index(Axis::C)], 715, 1e-9);
}

// The tool axis along the C axis: C is free, kept where it stood; the tip is still exact.
TEST(Kinematics, ATheToolAlongARotaryAxisKeepsThatAxisWhereItStood) {
  const Config c = machines()[0].config;  // A/C trunnion: A = 0 puts the tool along C
  Pose from{};
  from[index(Axis::A)] = 0.3;
  from[index(Axis::C)] = 123.4;
  const ToolPose want{{10, 20, 30}, {0, 0, 1}};
  const Inverse j = inverse(c, want, 75, from);
  EXPECT_EQ(j.status, Solve::Singular);
  EXPECT_NEAR(j.joints[index(Axis::A)], 0, 1e-9);
  EXPECT_NEAR(j.joints[index(Axis::C)], 123.4, 1e-9);
  EXPECT_LE(distance(forward(c, j.joints, 75).tip_mm, want.tip_mm), 1e-9);

  const Config head = machines()[2].config;  // B/C head: B = 0 puts the tool along C
  const Inverse h = inverse(head, want, 75, from);
  EXPECT_EQ(h.status, Solve::Singular);
  EXPECT_NEAR(h.joints[index(Axis::C)], 123.4, 1e-9);
  EXPECT_LE(distance(forward(head, h.joints, 75).tip_mm, want.tip_mm), 1e-9);
}

// A nutating head (B at 45° to C) reaches only the directions within 90° of Z; a zero tool axis
// reaches nothing.
TEST(Kinematics, ADirectionOutOfReachOrOfNoLengthIsUnreachable) {
  const Config nutating = machines()[5].config;
  const Pose from{};
  EXPECT_EQ(inverse(nutating, {{0, 0, 0}, {1, 0, -0.2}}, 100, from).status, Solve::Unreachable);
  EXPECT_NE(inverse(nutating, {{0, 0, 0}, {1, 0, 0.2}}, 100, from).status, Solve::Unreachable);
  const Inverse none = inverse(machines()[0].config, {{0, 0, 0}, {0, 0, 0}}, 100, from);
  EXPECT_EQ(none.status, Solve::Unreachable);
  EXPECT_EQ(none.joints, from);
}

// Identity: the tip is the joints less the tool length along Z, the inverse gives them back
// exactly, and the rotary joints are untouched.
TEST(Kinematics, IdentityIsTheJointsLessTheToolLength) {
  const Config id{};
  Pose j{};
  j[0] = 1.25;
  j[1] = -7.5;
  j[2] = 30.125;
  j[index(Axis::C)] = 12;
  const ToolPose t = forward(id, j, 10);
  EXPECT_EQ(t.tip_mm, (Vec3{1.25, -7.5, 20.125}));
  EXPECT_EQ(t.axis, (Vec3{0, 0, 1}));
  const Inverse back = inverse(id, t, 10, j);
  EXPECT_EQ(back.status, Solve::Ok);
  EXPECT_EQ(back.joints, j);
  const Jacobian jac = jacobian(id, j, 10);
  EXPECT_EQ(jac[0][0], 1);
  EXPECT_EQ(jac[2][2], 1);
  EXPECT_EQ(jac[0][3], 0);
  EXPECT_EQ(jac[5][4], 0);
}

TEST(Kinematics, AConfigurationThatCannotTurnTheToolIsRefused) {
  Config c{Structure::TableTable, {axis(Axis::A, {1, 0, 0}, {}), axis(Axis::C, {0, 0, 0}, {})}};
  EXPECT_EQ(prepare(c), ConfigError::ZeroDirection);
  c.rotary[1].direction = {2, 0, 0};
  EXPECT_EQ(prepare(c), ConfigError::ParallelAxes);
  c.rotary[1] = axis(Axis::A, {0, 0, 1}, {});
  EXPECT_EQ(prepare(c), ConfigError::SameJoint);
  c.rotary[1] = axis(Axis::Z, {0, 0, 1}, {});
  EXPECT_EQ(prepare(c), ConfigError::NotRotary);
  c.rotary[1] = axis(Axis::C, {0, 0, 3}, {});
  EXPECT_EQ(prepare(c), ConfigError::Ok);
  EXPECT_EQ(c.rotary[1].direction, (Vec3{0, 0, 1}));
  EXPECT_STREQ(to_string(ConfigError::ParallelAxes),
               "the two rotary axes are parallel: they cannot turn the tool onto every direction");
}
