// SPDX-License-Identifier: GPL-3.0-or-later
// Fanuc coordinate transforms: exact cases, and seeded property tests that transformed points
// and arcs keep their geometry (distances scale, arcs stay on their circle and turn the way
// the transformed path goes).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "opencnc/gcode/transforms.hpp"

using namespace opencnc;
using namespace opencnc::gcode;

namespace {

constexpr double kPi = 3.14159265358979323846;

Pose xyz(double x, double y, double z = 0) {
  Pose p;
  p[Axis::X] = x;
  p[Axis::Y] = y;
  p[Axis::Z] = z;
  return p;
}

TransformState rotation(canon::Plane plane, double c1, double c2, double deg) {
  TransformState t;
  t.rotating = true;
  t.rotation_plane = plane;
  t.rotation_centre1 = c1;
  t.rotation_centre2 = c2;
  t.rotation_deg = deg;
  return t;
}

}  // namespace

TEST(Transforms, QuarterTurnsAreExact) {
  for (int k = -8; k <= 8; ++k) {
    double s, c;
    sin_cos_deg(90.0 * k, s, c);
    EXPECT_EQ(s * s + c * c, 1.0);
    EXPECT_TRUE(s == 0.0 || std::fabs(s) == 1.0);
  }
  double s, c;
  sin_cos_deg(30, s, c);
  EXPECT_NEAR(s, 0.5, 1e-15);
}

TEST(Transforms, RotationAboutACentre) {
  const TransformState t = rotation(canon::Plane::XY, 10, 5, 90);
  const Pose p = transform_point(t, xyz(20, 5, 3));
  EXPECT_EQ(p[Axis::X], 10.0);
  EXPECT_EQ(p[Axis::Y], 15.0);
  EXPECT_EQ(p[Axis::Z], 3.0);
  // ZX plane (G18): the first axis is Z, the second X; a quarter turn takes +Z to +X.
  const TransformState g18 = rotation(canon::Plane::XZ, 0, 0, 90);
  const Pose q = transform_point(g18, xyz(0, 7, 1));
  EXPECT_EQ(q[Axis::X], 1.0);
  EXPECT_EQ(q[Axis::Z], 0.0);
  EXPECT_EQ(q[Axis::Y], 7.0);
}

TEST(Transforms, MirrorThenScaleThenRotate) {
  TransformState t = rotation(canon::Plane::XY, 0, 0, 90);
  t.mirror_axes = 1u << index(Axis::X);
  t.mirror_at[Axis::X] = 5;
  t.scaling = true;
  t.scale = {2, 2, 1};
  // (1, 1) → mirror about X = 5 → (9, 1) → scale 2 → (18, 2) → rotate 90° → (-2, 18).
  const Pose p = transform_point(t, xyz(1, 1));
  EXPECT_EQ(p[Axis::X], -2.0);
  EXPECT_EQ(p[Axis::Y], 18.0);
  // Stages can be cut short (the centres of later stages go through the earlier ones only).
  const Pose m = transform_point(t, xyz(1, 1), TransformStage::Mirror);
  EXPECT_EQ(m[Axis::X], 9.0);
  const Pose s = transform_point(t, xyz(1, 1), TransformStage::Scale);
  EXPECT_EQ(s[Axis::X], 18.0);
}

TEST(Transforms, ArcsReverseUnderAnOddNumberOfReflections) {
  canon::ArcFeed a;   // quarter circle, centre (0, 0), from (1, 0) to (0, 1), counterclockwise
  a.first_end = 0, a.second_end = 1, a.first_center = 0, a.second_center = 0, a.rotation = 1;
  a.end = xyz(0, 1);
  TransformState mirror_x;
  mirror_x.mirror_axes = 1u << index(Axis::X);
  canon::ArcFeed b = a;
  ASSERT_EQ(transform_arc(mirror_x, b), ArcTransform::Ok);
  EXPECT_EQ(b.rotation, -1);
  EXPECT_EQ(b.first_end, 0.0);
  EXPECT_EQ(b.end[Axis::Y], 1.0);
  TransformState both = mirror_x;
  both.mirror_axes |= 1u << index(Axis::Y);
  canon::ArcFeed c = a;
  ASSERT_EQ(transform_arc(both, c), ArcTransform::Ok);
  EXPECT_EQ(c.rotation, 1);
  EXPECT_EQ(c.second_end, -1.0);
  TransformState negative;   // a negative factor is a reflection too
  negative.scaling = true;
  negative.scale = {-1, 1, 1};
  canon::ArcFeed d = a;
  ASSERT_EQ(transform_arc(negative, d), ArcTransform::Ok);
  EXPECT_EQ(d.rotation, -1);
}

TEST(Transforms, ArcsRefuseNonUniformScalingAndOtherPlanes) {
  canon::ArcFeed a;
  a.first_end = 1, a.rotation = 1;
  TransformState t;
  t.scaling = true;
  t.scale = {2, 0.5, 1};
  canon::ArcFeed b = a;
  EXPECT_EQ(transform_arc(t, b), ArcTransform::NonUniformScale);
  EXPECT_EQ(b.first_end, 1.0);   // unchanged
  // The plane's own factors decide: X and Z equal is fine for a ZX arc, even with Y different.
  t.scale = {2, 0.5, 2};
  b.plane = canon::Plane::XZ;
  EXPECT_EQ(transform_arc(t, b), ArcTransform::Ok);
  const TransformState r = rotation(canon::Plane::XY, 0, 0, 30);
  canon::ArcFeed c = a;
  c.plane = canon::Plane::YZ;
  EXPECT_EQ(transform_arc(r, c), ArcTransform::OtherPlane);
}

// Seeded property test: for random transforms that keep arcs arcs, and random arcs in the
// XY plane, the transformed end point is the transform of the end point, the transformed arc
// is a circle through the transformed start, and it passes through the transformed midpoint
// of the original arc on its way (so its direction is right).
TEST(Transforms, RandomArcsKeepTheirGeometry) {
  std::mt19937_64 rng(20240601);
  std::uniform_real_distribution<double> coord(-50, 50), unit(0, 1);
  for (int n = 0; n < 20000; ++n) {
    TransformState t;
    if (unit(rng) < 0.6) {
      t.mirror_axes = static_cast<std::uint16_t>(rng() % 4);   // X and/or Y
      t.mirror_at[Axis::X] = coord(rng);
      t.mirror_at[Axis::Y] = coord(rng);
    }
    if (unit(rng) < 0.6) {
      t.scaling = true;
      const double f = 0.1 + 3 * unit(rng);
      t.scale = {unit(rng) < 0.2 ? -f : f, unit(rng) < 0.2 ? -f : f, 0.5 + unit(rng)};
      t.scale_centre = xyz(coord(rng), coord(rng), coord(rng));
    }
    if (unit(rng) < 0.6) t = [&] {
        TransformState r = t;
        r.rotating = true;
        r.rotation_plane = canon::Plane::XY;
        r.rotation_centre1 = coord(rng);
        r.rotation_centre2 = coord(rng);
        r.rotation_deg = 360 * unit(rng) - 180;
        return r;
      }();
    const double cx = coord(rng), cy = coord(rng), radius = 0.5 + 20 * unit(rng);
    const double a0 = 2 * kPi * unit(rng), sweep = (0.05 + 1.9 * unit(rng)) * kPi;
    const int dir = unit(rng) < 0.5 ? 1 : -1;
    const double a1 = a0 + dir * sweep, am = a0 + dir * sweep / 2;
    const Pose start = xyz(cx + radius * std::cos(a0), cy + radius * std::sin(a0), coord(rng));
    const Pose mid = xyz(cx + radius * std::cos(am), cy + radius * std::sin(am));
    canon::ArcFeed arc;
    arc.plane = canon::Plane::XY;
    arc.first_end = cx + radius * std::cos(a1);
    arc.second_end = cy + radius * std::sin(a1);
    arc.first_center = cx;
    arc.second_center = cy;
    arc.rotation = dir;
    arc.axis_end = coord(rng);
    arc.end = xyz(arc.first_end, arc.second_end, arc.axis_end);
    const Pose end_t = transform_point(t, arc.end);
    ASSERT_EQ(transform_arc(t, arc), ArcTransform::Ok);
    EXPECT_NEAR(arc.first_end, end_t[Axis::X], 1e-9);
    EXPECT_NEAR(arc.axis_end, end_t[Axis::Z], 1e-9);
    const Pose s = transform_point(t, start), m = transform_point(t, mid);
    const double r_start = std::hypot(s[Axis::X] - arc.first_center, s[Axis::Y] - arc.second_center);
    const double r_end = std::hypot(arc.first_end - arc.first_center, arc.second_end - arc.second_center);
    ASSERT_NEAR(r_start, r_end, 1e-9 * (1 + r_start));
    // Angles from the transformed start, in the transformed arc's direction: the midpoint
    // comes before the end.
    auto angle = [&](const Pose& p) {
      double v = std::atan2(p[Axis::Y] - arc.second_center, p[Axis::X] - arc.first_center) -
                 std::atan2(s[Axis::Y] - arc.second_center, s[Axis::X] - arc.first_center);
      if (arc.rotation < 0) v = -v;
      while (v < 0) v += 2 * kPi;
      while (v >= 2 * kPi) v -= 2 * kPi;
      return v;
    };
    EXPECT_LT(angle(m), angle(end_t)) << "arc " << n;
  }
}

// Seeded property test: rotation and uniform scaling multiply every distance in the plane by
// the factor's magnitude; mirroring keeps distances.
TEST(Transforms, RandomPointsKeepDistancesUpToTheScale) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> coord(-100, 100), unit(0, 1);
  for (int n = 0; n < 20000; ++n) {
    TransformState t = rotation(canon::Plane::XY, coord(rng), coord(rng), 720 * unit(rng) - 360);
    t.mirror_axes = static_cast<std::uint16_t>(rng() % 8);
    t.mirror_at = xyz(coord(rng), coord(rng), coord(rng));
    t.scaling = unit(rng) < 0.5;
    const double f = (unit(rng) < 0.5 ? -1 : 1) * (0.01 + 5 * unit(rng));
    t.scale = {f, f, f};
    const Pose p = xyz(coord(rng), coord(rng), coord(rng)), q = xyz(coord(rng), coord(rng), coord(rng));
    const Pose a = transform_point(t, p), b = transform_point(t, q);
    const double k = t.scaling ? std::fabs(f) : 1.0;
    const double d0 = std::hypot(p[Axis::X] - q[Axis::X], p[Axis::Y] - q[Axis::Y], p[Axis::Z] - q[Axis::Z]);
    const double d1 = std::hypot(a[Axis::X] - b[Axis::X], a[Axis::Y] - b[Axis::Y], a[Axis::Z] - b[Axis::Z]);
    ASSERT_NEAR(d1, k * d0, 1e-9 * (1 + d1));
  }
}
