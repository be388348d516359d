// SPDX-License-Identifier: GPL-3.0-or-later
// The arc words every layer shares: the planes' axes and the sweep from LinuxCNC's turn count.
#include <gtest/gtest.h>

#include <numbers>

#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::canon {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(ArcGeometry, EachPlaneHasARightHandedTriple) {
  struct Row {
    Plane plane;
    int first, second, normal, base;
    const char* name;
  };
  const Row rows[] = {{Plane::XY, 0, 1, 2, 0, "XY"}, {Plane::YZ, 1, 2, 0, 0, "YZ"},
                      {Plane::XZ, 2, 0, 1, 0, "XZ"}, {Plane::UV, 6, 7, 8, 6, "UV"},
                      {Plane::VW, 7, 8, 6, 6, "VW"}, {Plane::UW, 8, 6, 7, 6, "UW"}};
  for (const Row& r : rows) {
    const PlaneAxes a = plane_axes(r.plane);
    EXPECT_EQ(a.first, r.first) << r.name;
    EXPECT_EQ(a.second, r.second) << r.name;
    EXPECT_EQ(a.normal, r.normal) << r.name;
    EXPECT_EQ(plane_base(r.plane), r.base) << r.name;
    EXPECT_STREQ(plane_name(r.plane), r.name);
    // first × second = +normal: the triple is a cyclic shift of (0, 1, 2) within its base.
    EXPECT_EQ((a.first - r.base + 1) % 3, a.second - r.base) << r.name;
    EXPECT_EQ((a.second - r.base + 1) % 3, a.normal - r.base) << r.name;
  }
}

TEST(ArcGeometry, TheSweepFollowsTheDirectionAndTheTurns) {
  EXPECT_DOUBLE_EQ(arc_sweep(kPi / 2, 1), kPi / 2);             // G3 a quarter
  EXPECT_DOUBLE_EQ(arc_sweep(kPi / 2, -1), kPi / 2 - 2 * kPi);  // G2 the long way
  EXPECT_DOUBLE_EQ(arc_sweep(-kPi / 2, -1), -kPi / 2);
  EXPECT_DOUBLE_EQ(arc_sweep(-kPi / 2, 1), 1.5 * kPi);
  EXPECT_DOUBLE_EQ(arc_sweep(0, 1), 2 * kPi);  // end on start: a whole circle
  EXPECT_DOUBLE_EQ(arc_sweep(0, -1), -2 * kPi);
  EXPECT_DOUBLE_EQ(arc_sweep(kPi / 2, 3), kPi / 2 + 4 * kPi);  // P3: two more circles
  EXPECT_DOUBLE_EQ(arc_sweep(-kPi / 2, -3), -kPi / 2 - 4 * kPi);
  EXPECT_DOUBLE_EQ(arc_sweep(kPi / 2, 0), kPi / 2);  // 0 taken as 1
}

}  // namespace
}  // namespace opencnc::canon
