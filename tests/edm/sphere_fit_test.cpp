// SPDX-License-Identifier: GPL-3.0-or-later
// The least-squares sphere centre: exact points give the centre back, the residuals are distances,
// and points that cannot fix a centre give nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "opencnc/edm/b_axis_fit.hpp"
#include "opencnc/edm/sphere_fit.hpp"

namespace opencnc::edm {
namespace {

using P = Vec3;

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

/// The sphere's centres (plus an electrode's offsets) with B at each angle, about a known axis.
std::vector<P> turned_centres(const config::ReferenceSphereProfile& truth, const P& electrode,
                              const std::vector<double>& angles) {
  std::vector<P> out;
  for (const double b : angles) {
    P c = sphere_centre_at(truth, b);
    for (std::size_t i = 0; i < 3; ++i) c[i] += electrode[i];
    out.push_back(c);
  }
  return out;
}

config::ReferenceSphereProfile sphere_on_b(double b_deg) {
  config::ReferenceSphereProfile s;
  s.position = {120, 80, -70};
  s.b_deg = b_deg;
  s.has_b_axis = true;
  s.b_axis = {120.012, -90.015};
  const double n = std::hypot(0.0003, 1.0, -0.0002);
  s.b_axis_direction = {0.0003 / n, 1 / n, -0.0002 / n};
  return s;
}

TEST(BAxisFit, ExactCentresGiveTheAxisWhateverTheElectrodesOffsets) {
  for (const double b : {0.0, 25.0}) {  // the profile's position given with B at 0 or at 25°
    const config::ReferenceSphereProfile truth = sphere_on_b(b);
    config::ReferenceSphereProfile nominal = truth;
    nominal.b_axis = {120, -90};
    nominal.b_axis_direction = {0, 1, 0};
    const std::vector<double> angles{-45, 10, 45, 80};
    const auto fit = fit_b_axis(angles, turned_centres(truth, {0.3, -0.2, 40.5}, angles), nominal);
    ASSERT_TRUE(fit.has_value());
    EXPECT_NEAR(fit->axis.crossing[0], 120.012, 1e-9);
    EXPECT_NEAR(fit->axis.crossing[1], -90.015, 1e-9);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(fit->axis.direction[i], truth.b_axis_direction[i], 1e-12);
    EXPECT_LT(fit->max_residual_mm, 1e-9);
    EXPECT_NEAR(fit->radius_mm, std::hypot(0.012, 20.015), 1e-6);
  }
}

TEST(BAxisFit, TheDirectionTurnsWithBWhateverTheAnglesOrder) {
  // −90°, 0°, 90°: the first and last are half a turn apart, which says nothing of the sense.
  const config::ReferenceSphereProfile truth = sphere_on_b(0);
  for (const std::vector<double>& angles :
       {std::vector<double>{-90, 0, 90}, std::vector<double>{90, -90, 0}}) {
    const auto fit = fit_b_axis(angles, turned_centres(truth, {0, 0, 0}, angles), truth);
    ASSERT_TRUE(fit.has_value());
    EXPECT_GT(fit->axis.direction[1], 0.99);
    EXPECT_NEAR(fit->axis.crossing[0], 120.012, 1e-9);
    EXPECT_LT(fit->max_residual_mm, 1e-9);
  }
}

TEST(BAxisFit, ResidualsSayHowFarACentreIsFromTheTurnedSphere) {
  const config::ReferenceSphereProfile truth = sphere_on_b(0);
  const std::vector<double> angles{-40, -20, 0, 20, 40};
  std::vector<P> centres = turned_centres(truth, {0, 0, 0}, angles);
  centres[1][1] += 0.004;  // one measurement 4 µm off along the axis
  const auto fit = fit_b_axis(angles, centres, truth);
  ASSERT_TRUE(fit.has_value());
  EXPECT_GT(fit->max_residual_mm, 0.002);
  EXPECT_LT(fit->max_residual_mm, 0.004);
  EXPECT_EQ(fit->residuals_mm.size(), 5u);
  EXPECT_GT(fit->residuals_mm[1], fit->residuals_mm[4]);
}

TEST(BAxisFit, RefusesCentresThatFixNoAxis) {
  const config::ReferenceSphereProfile truth = sphere_on_b(0);
  const std::vector<double> two{0, 40};
  EXPECT_FALSE(fit_b_axis(two, turned_centres(truth, {0, 0, 0}, two), truth).has_value()) << "two angles";
  const std::vector<double> same{0, 40, 40};
  EXPECT_FALSE(fit_b_axis(same, turned_centres(truth, {0, 0, 0}, same), truth).has_value());
  const std::vector<double> three{-40, 0, 40};
  const std::vector<P> still(3, P{120, 80, -70});  // a sphere that does not turn with B
  EXPECT_FALSE(fit_b_axis(three, still, truth).has_value());
}

}  // namespace
}  // namespace opencnc::edm
