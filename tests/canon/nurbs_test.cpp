// SPDX-License-Identifier: GPL-3.0-or-later
// NURBS evaluation and chord splitting: exact curves (Bezier, circle), seeded random curves
// checked against the chord tolerance, and ProgramBuilder's splitting with its segment ids.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "opencnc/canon/nurbs.hpp"
#include "opencnc/canon/program_builder.hpp"

using namespace opencnc;
using namespace opencnc::canon;

namespace {

double distance_to_segment(double px, double py, const CurvePoint& a, const CurvePoint& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((px - a.x) * dx + (py - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(px - (a.x + t * dx), py - (a.y + t * dy));
}

// Every chord i covers the parameters from vertex i-1 to vertex i; dense samples of the curve
// there must lie within `tol` of it.
void expect_within_tolerance(const std::vector<NurbsPoint>& pts, int order, double tol,
                             const std::vector<CurvePoint>& chords) {
  CurvePoint prev{pts.front().x, pts.front().y, 0};
  for (const CurvePoint& v : chords) {
    ASSERT_GT(v.u, prev.u);
    for (int s = 1; s < 8; ++s) {
      const double u = prev.u + (v.u - prev.u) * s / 8.0;
      const CurvePoint c = nurbs_point(pts, order, u);
      ASSERT_LE(distance_to_segment(c.x, c.y, prev, v), tol * (1 + 1e-9) + 1e-12) << "u " << u;
    }
    prev = v;
  }
}

}  // namespace

TEST(Nurbs, KnotsAreLinuxCncs) {
  EXPECT_EQ(nurbs_knots(4, 4), (std::vector<double>{0, 0, 0, 0, 1, 1, 1, 1}));
  EXPECT_EQ(nurbs_knots(5, 3), (std::vector<double>{0, 0, 0, 1, 2, 3, 3, 3}));
  EXPECT_EQ(nurbs_knots(6, 4), (std::vector<double>{0, 0, 0, 0, 1, 2, 3, 3, 3, 3}));
}

TEST(Nurbs, CubicWithUnitWeightsIsTheBezierCurve) {
  const std::vector<NurbsPoint> p{{0, 0, 1}, {1, 2, 1}, {4, 3, 1}, {5, 0, 1}};
  for (double u : {0.0, 0.1, 0.37, 0.5, 0.93, 1.0}) {
    const double a = (1 - u) * (1 - u) * (1 - u), b = 3 * u * (1 - u) * (1 - u), c = 3 * u * u * (1 - u), d = u * u * u;
    const CurvePoint q = nurbs_point(p, 4, u);
    EXPECT_NEAR(q.x, a * 0 + b * 1 + c * 4 + d * 5, 1e-12);
    EXPECT_NEAR(q.y, a * 0 + b * 2 + c * 3 + d * 0, 1e-12);
  }
}

// A quadratic with weights 1, cos(θ/2), 1 is a circular arc of angle θ: every point is on the
// circle, and the chords of the split stay within the tolerance of it.
TEST(Nurbs, WeightedQuadraticIsACircle) {
  const double r = 10, theta = std::numbers::pi / 2;
  const std::vector<NurbsPoint> p{{r, 0, 1}, {r, r * std::tan(theta / 2), std::cos(theta / 2)}, {0, r, 1}};
  for (int i = 0; i <= 20; ++i) {
    const CurvePoint q = nurbs_point(p, 3, i / 20.0);
    EXPECT_NEAR(std::hypot(q.x, q.y), r, 1e-12);
  }
  const double tol = 0.0005;
  const auto chords = tessellate_nurbs(p, 3, tol);
  // Sagitta of a chord c on radius r is c²/8r: a chord no longer than sqrt(8 r tol) keeps it.
  const double arc = r * theta, longest = std::sqrt(8 * r * tol);
  EXPECT_GE(chords.size(), static_cast<std::size_t>(arc / longest));
  EXPECT_LE(chords.size(), static_cast<std::size_t>(4 * arc / longest) + 1);
  double worst = 0;
  CurvePoint prev{r, 0, 0};
  for (const CurvePoint& v : chords) {
    worst = std::max(worst, r - std::hypot((prev.x + v.x) / 2, (prev.y + v.y) / 2));   // sagitta
    prev = v;
  }
  EXPECT_LE(worst, tol);
  EXPECT_EQ(chords.back().x, 0.0);
  EXPECT_EQ(chords.back().y, r);
}

TEST(NurbsProperty, RandomCurvesStayWithinTheTolerance) {
  std::mt19937_64 rng(5150);
  std::uniform_real_distribution<double> coord(-20, 20), weight(0.2, 5.0);
  for (int trial = 0; trial < 100; ++trial) {
    const int count = 3 + static_cast<int>(rng() % 10);
    const int order = 2 + static_cast<int>(rng() % static_cast<unsigned>(std::min(count, 6) - 1));
    std::vector<NurbsPoint> pts;
    for (int i = 0; i < count; ++i) pts.push_back({coord(rng), coord(rng), trial % 2 ? weight(rng) : 1.0});
    const double tol = trial % 3 == 0 ? 0.002 : 0.02;   // lean: the sampling below is the cost
    SCOPED_TRACE(testing::Message() << "trial " << trial << " count " << count << " order " << order);
    const auto chords = tessellate_nurbs(pts, order, tol);
    ASSERT_FALSE(chords.empty());
    EXPECT_EQ(chords.back().x, pts.back().x);   // the end is exact
    EXPECT_EQ(chords.back().y, pts.back().y);
    for (std::size_t i = 0; i + 1 < chords.size(); ++i) {   // vertices are curve points
      const CurvePoint c = nurbs_point(pts, order, chords[i].u);
      EXPECT_NEAR(c.x, chords[i].x, 1e-9);
      EXPECT_NEAR(c.y, chords[i].y, 1e-9);
    }
    expect_within_tolerance(pts, order, tol, chords);
  }
}

TEST(Nurbs, NonPositiveWeightsFallBackToTheControlPolygon) {
  // LinuxCNC gives a first G5.2 point without P the weight -1.
  const std::vector<NurbsPoint> p{{0, 0, 1}, {1, 1, -1}, {2, 0, 1}, {3, 1, 1}};
  const auto chords = tessellate_nurbs(p, 3, 0.0005);
  ASSERT_EQ(chords.size(), 3u);
  EXPECT_EQ(chords[0].x, 1.0);
  EXPECT_EQ(chords[2].y, 1.0);
}

// ProgramBuilder: a spline becomes chord moves of one segment; ids of later segments shift
// by the extra moves, and the chords follow the curve through units, offsets and rotation.
TEST(ProgramBuilderNurbs, SplitsIntoChordsWithStableIds) {
  ProgramBuilder b(kXyzabc);
  b.use_length_units(Units::Inch);
  Pose g5x{};
  g5x[0] = 1;
  g5x[1] = -2;
  g5x[2] = 0.5;
  b.set_g5x_offset(1, g5x);
  b.set_xy_rotation(30);
  b.set_feed_rate(10);
  Pose p{};
  p[2] = 0.25;
  b.straight_feed(0, p);   // segment 0
  const std::vector<NurbsPoint> pts{{0, 0, 1}, {1, 2, 2}, {3, 2, 0.5}, {4, 0, 1}};
  b.nurbs_feed(1, 4, pts);   // segment 1
  Pose e = p;
  e[0] = 5;
  b.straight_feed(2, e);   // segment 2
  const Program& prog = b.program();
  const std::size_t chords = prog.size() - 2;
  ASSERT_GT(chords, 10u);
  EXPECT_EQ(prog.segment_of(0), 0u);
  for (std::size_t m = 1; m <= chords; ++m) {
    EXPECT_EQ(prog.segment_of(m), 1u);
    EXPECT_TRUE(prog.move(m).flags & kCurveChord);
    EXPECT_NEAR(prog.end(m)[2], b.to_machine(p)[2], 1e-12);   // Z stays
  }
  EXPECT_EQ(prog.segment_of(chords + 1), 2u);
  EXPECT_EQ(prog.first_move_of(1), 1u);
  EXPECT_EQ(prog.moves_of(1), chords);
  EXPECT_EQ(prog.first_move_of(2), chords + 1);
  EXPECT_EQ(prog.moves_of(2), 1u);
  // The last chord ends exactly where the curve ends (in machine coordinates).
  Pose last = p;
  last[0] = 4;
  last[1] = 0;
  const Pose want = b.to_machine(last);
  EXPECT_NEAR(prog.end(chords)[0], want[0], 1e-12);
  EXPECT_NEAR(prog.end(chords)[1], want[1], 1e-12);
  // Dense samples of the programmed curve, taken to machine coordinates, lie within the
  // tolerance of the chords.
  for (int s = 0; s <= 100; ++s) {
    const CurvePoint c = nurbs_point(pts, 4, s / 100.0);
    Pose q = p;
    q[0] = c.x;
    q[1] = c.y;
    const Pose m = b.to_machine(q);
    double best = 1e9;
    for (std::size_t k = 1; k <= chords; ++k) {
      const Pose a0 = prog.start_of(k), a1 = prog.end(k);
      best = std::min(best, distance_to_segment(m[0], m[1], {a0[0], a0[1], 0}, {a1[0], a1[1], 0}));
    }
    EXPECT_LE(best, ProgramBuilder::kCurveToleranceMm * (1 + 1e-9)) << "sample " << s;
  }
}

TEST(ProgramBuilderNurbs, IdsFromAReplayStartAtTheFirstSegment) {
  ProgramBuilder b(kXyzabc);
  b.set_feed_rate(100);
  Pose p{};
  p[0] = 1;
  b.straight_feed(7, p);
  const std::vector<NurbsPoint> pts{{1, 0, 1}, {2, 3, 1}, {4, 0, 1}};
  b.nurbs_feed(8, 3, pts);
  p[0] = 9;
  b.straight_feed(9, p);
  const Program& prog = b.program();
  EXPECT_EQ(prog.segment_of(0), 7u);
  EXPECT_EQ(prog.segment_of(1), 8u);
  EXPECT_EQ(prog.segment_of(prog.size() - 1), 9u);
  EXPECT_EQ(prog.first_move_of(9), prog.size() - 1);
  EXPECT_EQ(prog.first_move_of(7), 0u);
}
