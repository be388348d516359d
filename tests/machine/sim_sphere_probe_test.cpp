// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated reference sphere turns with B about B's axis (right-handed about +Y), and the
// contact follows it.
#include <gtest/gtest.h>

#include "opencnc/machine/sim_sphere_probe.hpp"

namespace opencnc::machine {
namespace {

SimSphereTarget on_b(double b_at_centre_deg) {
  SimSphereTarget t;
  t.present = true;
  t.centre = {100, 50, -150};  // with B at b_at_centre_deg
  t.radius = 5;
  t.noise = 0;
  t.b_joint = 3;
  t.b_axis = {100, -170};  // 20 mm below the centre
  t.b_at_centre_deg = b_at_centre_deg;
  return t;
}

TEST(SimSphereProbe, TheSphereTurnsWithBAboutItsAxis) {
  SimSphereProbe p(on_b(0));
  p.turn(0);
  EXPECT_NEAR(p.centre()[0], 100, 1e-12);
  EXPECT_NEAR(p.centre()[2], -150, 1e-12);
  p.turn(90);  // +B turns +Z toward +X
  EXPECT_NEAR(p.centre()[0], 120, 1e-12);
  EXPECT_NEAR(p.centre()[1], 50, 1e-12);
  EXPECT_NEAR(p.centre()[2], -170, 1e-12);
  p.turn(-90);
  EXPECT_NEAR(p.centre()[0], 80, 1e-12);
  EXPECT_NEAR(p.centre()[2], -170, 1e-12);
  SimSphereProbe q(on_b(30));  // the centre given at B 30: there it stays
  q.turn(30);
  EXPECT_NEAR(q.centre()[0], 100, 1e-12);
  EXPECT_NEAR(q.centre()[2], -150, 1e-12);
}

TEST(SimSphereProbe, TheContactFollowsTheTurnedSphere) {
  SimSphereProbe p(on_b(0));
  SplitMix64 rng{3};
  p.set_electrode({0, 0, 0}, 0);
  const Vec3 top_at_0{100, 50, -145};  // the point tip on the sphere's top at B 0
  p.turn(0);
  EXPECT_NEAR(p.gap(top_at_0), 0, 1e-12);
  EXPECT_TRUE(p.update({100, 50, -145.0001}, rng));
  p.turn(90);  // the sphere has gone to X 120, Z −170: the same point is far from it
  EXPECT_GT(p.gap(top_at_0), 20);
  EXPECT_FALSE(p.update({100, 50, -145.0001}, rng));
  EXPECT_NEAR(p.gap({125, 50, -170}), 0, 1e-12);  // its +X side now
}

TEST(SimSphereProbe, ASphereNotOnBStaysPut) {
  SimSphereTarget t = on_b(0);
  t.b_joint = -1;
  SimSphereProbe p(t);
  p.turn(45);
  EXPECT_EQ(p.centre(), t.centre);
}

}  // namespace
}  // namespace opencnc::machine
