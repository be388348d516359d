// SPDX-License-Identifier: GPL-3.0-or-later
// The least-squares sphere centre: exact points give the centre back, the residuals are distances,
// and points that cannot fix a centre give nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "opencnc/controller/sphere_fit.hpp"

namespace opencnc::control {
namespace {

using P = std::array<double, 3>;

std::vector<P> touches(const P& c, double r) {  // four around the equator and the top
  return {{c[0] + r, c[1], c[2]},
          {c[0], c[1] + r, c[2]},
          {c[0] - r, c[1], c[2]},
          {c[0], c[1] - r, c[2]},
          {c[0], c[1], c[2] + r}};
}

TEST(SphereFit, FindsTheCentreOfExactTouchesFromAFarGuess) {
  const P c{100.2, 49.9, -99.5};
  const auto fit = fit_sphere(touches(c, 5), 5, {100, 50, -100});
  ASSERT_TRUE(fit.has_value());
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(fit->centre[i], c[i], 1e-12);
  EXPECT_LT(fit->max_residual, 1e-12);
  EXPECT_LE(fit->iterations, 10);
}

TEST(SphereFit, ResidualsAreDistancesFromTheSurface) {
  std::vector<P> pts = touches({0, 0, 0}, 5);
  pts[0][0] += 0.01;  // one touch 10 µm out
  const auto fit = fit_sphere(pts, 5, {0, 0, 0});
  ASSERT_TRUE(fit.has_value());
  ASSERT_EQ(fit->residuals.size(), 5u);
  // Least squares moves the centre 5 µm toward it: both X touches are then 5 µm outside.
  EXPECT_NEAR(fit->centre[0], 0.005, 1e-6);
  EXPECT_NEAR(fit->residuals[0], 0.005, 1e-6);
  EXPECT_NEAR(fit->residuals[2], 0.005, 1e-6);
  EXPECT_NEAR(fit->max_residual, 0.005, 1e-6);
}

TEST(SphereFit, RefusesPointsThatDoNotFixACentre) {
  EXPECT_FALSE(fit_sphere(std::vector<P>{{5, 0, 0}, {-5, 0, 0}}, 5, {0, 0, 0}).has_value()) << "two points";
  // Only the equator: the centre's height is free.
  const std::vector<P> ring{{5, 0, 0}, {0, 5, 0}, {-5, 0, 0}, {0, -5, 0}};
  EXPECT_FALSE(fit_sphere(ring, 5, {0, 0, 0}).has_value());
  EXPECT_FALSE(fit_sphere(std::vector<P>{{0, 0, 0}, {5, 0, 0}, {0, 5, 0}}, 5, {0, 0, 0}).has_value())
      << "a point on the guess";
}

}  // namespace
}  // namespace opencnc::control
