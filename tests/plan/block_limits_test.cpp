// SPDX-License-Identifier: GPL-3.0-or-later
// Block limits of Bézier blocks with jerk limits: the cap, budget and jerk budget keep every axis
// within its limits along the whole block (sampled densely, derivatives by de Casteljau here),
// and the jerk cap goes above half of J where the pieces with a large g''' carry little tangent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "block_limits.hpp"

using namespace opencnc;
using plan::detail::LimitParams;
using plan::detail::RawLimits;
using traj::BlockKind;
using traj::MotionBlock;

namespace {

constexpr double kJ = 1e5, kA = 1000, kV = 100;

LimitParams jerk_params() {
  LimitParams p;
  p.machine = plan::MachineLimits::uniform(AxisMask::from_letters("XYZ"), kV, kA, kJ);
  p.filter_s = kA / kJ;
  return p;
}

Pose& point(MotionBlock& b, int k) {
  Pose* pts[] = {&b.base, &b.u, &b.w, &b.lin, &b.p4, &b.p5};
  return *pts[k];
}

/// The m-th derivative in t of the Bernstein polynomial with coefficients c[0..n] at t.
double bezier_derivative(const double* c, int n, int m, double t) {
  double q[6];
  for (int k = 0; k <= n; ++k) q[k] = c[k];
  int deg = n;
  for (int d = 0; d < m; ++d, --deg) {
    for (int k = 0; k < deg; ++k) q[k] = deg * (q[k + 1] - q[k]);
  }
  for (int level = deg; level > 0; --level) {
    for (int k = 0; k < level; ++k) q[k] += t * (q[k + 1] - q[k]);
  }
  return deg >= 0 ? q[0] : 0.0;
}

/// Checks every axis at v = cap with |a| = accel and |j| = jerk, in the worst combination of signs.
void expect_within_limits(const MotionBlock& b, const RawLimits& r, const LimitParams& p) {
  const int n = b.kind == BlockKind::Quintic ? 5 : 3;
  const double L = b.length, v = r.cap, a = r.accel, j = r.jerk;
  EXPECT_GE(j * p.filter_s, a * (1 - 1e-9));
  for (int i = 0; i < 3; ++i) {
    double c[6];
    for (int k = 0; k <= n; ++k) c[k] = point(const_cast<MotionBlock&>(b), k)[i];
    for (int s = 0; s <= 4000; ++s) {
      const double t = s / 4000.0;
      const double g1 = std::fabs(bezier_derivative(c, n, 1, t)) / L;
      const double g2 = std::fabs(bezier_derivative(c, n, 2, t)) / (L * L);
      const double g3 = std::fabs(bezier_derivative(c, n, 3, t)) / (L * L * L);
      ASSERT_LE(g1 * v, kV * (1 + 1e-9));
      ASSERT_LE(g1 * a + g2 * v * v, kA * (1 + 1e-9)) << "axis " << i << " t " << t;
      ASSERT_LE(g1 * j + 3 * g2 * v * a + g3 * v * v * v, kJ * (1 + 1e-9)) << "axis " << i << " t " << t;
    }
  }
}

/// Length of a Bézier block by summing chords (the limits need no exact length).
double chord_length(MotionBlock& b) {
  const int n = b.kind == BlockKind::Quintic ? 5 : 3;
  double len = 0, prev[3] = {};
  for (int s = 0; s <= 2000; ++s) {
    double x[3];
    for (int i = 0; i < 3; ++i) {
      double c[6];
      for (int k = 0; k <= n; ++k) c[k] = point(b, k)[i];
      x[i] = bezier_derivative(c, n, 0, s / 2000.0);
    }
    if (s > 0) len += std::hypot(x[0] - prev[0], x[1] - prev[1], x[2] - prev[2]);
    std::copy(x, x + 3, prev);
  }
  return len;
}

}  // namespace

TEST(BlockLimits, RandomBeziersWithJerkLimitsKeepEveryAxisWithinItsLimits) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> coord(-1.0, 1.0), scale(0.01, 5.0), feed(1.0, 150.0);
  const LimitParams p = jerk_params();
  for (int trial = 0; trial < 400; ++trial) {
    MotionBlock b{};
    b.kind = trial % 2 ? BlockKind::Quintic : BlockKind::Bezier;
    b.feed_class = traj::FeedClass::Feed;
    b.feed = feed(rng);
    const int n = b.kind == BlockKind::Quintic ? 5 : 3;
    const double sc = scale(rng);
    for (int k = 0; k <= n; ++k) {
      for (int i = 0; i < 3; ++i) point(b, k)[i] = sc * coord(rng);
    }
    b.length = chord_length(b);
    const RawLimits r = plan::detail::block_limits(b, 2 * b.feed, p);
    ASSERT_GT(r.cap, 0);
    expect_within_limits(b, r, p);
  }
}

TEST(BlockLimits, AQuinticCornerBlendTakesMoreThanHalfOfJAtItsCap) {
  // A curvature-continuous blend from a line along X into one along Y (control points as
  // make_g2_curve places them, zero curvature at both ends): its g''' is largest where it leaves
  // and joins the lines, across the tangent, so the cap may rise above (½J/max|g'''|)^⅓.
  MotionBlock b{};
  b.kind = BlockKind::Quintic;
  b.feed_class = traj::FeedClass::Feed;
  b.feed = 100;
  const double d = 1.0, h = d / 3;  // g'''(0) along Y only
  b.base[0] = -d;
  b.u[0] = -d + h;
  b.w[0] = -d + 2 * h;
  b.lin[1] = d - 2 * h;
  b.p4[1] = d - h;
  b.p5[1] = d;
  b.length = chord_length(b);
  const LimitParams p = jerk_params();
  const RawLimits r = plan::detail::block_limits(b, 200, p);
  double d1[kAxisCount], d2[kAxisCount], d3[kAxisCount];
  plan::detail::derivative_bounds(b, d1, d2, d3);
  const double half = std::cbrt(0.5 * kJ / std::max(d3[0], d3[1]));
  EXPECT_GT(r.cap, 1.05 * half);
  expect_within_limits(b, r, p);
}
