// SPDX-License-Identifier: GPL-3.0-or-later
// CouplingLaw: each law against its definition (numerical integral of 360/p, the cam's points),
// slopes and curvatures against finite differences, C1 at a cam's points, both signs of travel,
// and the preflight's extremes never below a dense sampling.
#include <gtest/gtest.h>

#include <cmath>

#include "opencnc/motion/coupling.hpp"

namespace opencnc::motion {
namespace {

/// 360·∫₀ᵈ dz/p(z) by Simpson's rule (the definition the closed forms must meet).
double integral_deg(const CouplingLaw& law, double d) {
  const int n = 2000;
  const double h = d / n;
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    sum += w / law.pitch_at(i * h);
  }
  return 360.0 * sum * h / 3.0;
}

CouplingTable table(std::initializer_list<std::pair<double, double>> points) {
  CouplingTable t;
  for (const auto& [m, v] : points) {
    t.master[static_cast<std::size_t>(t.count)] = m;
    t.value[static_cast<std::size_t>(t.count++)] = v;
  }
  return t;
}

void expect_derivatives(const CouplingLaw& law, double d) {
  const double h = 1e-4;
  EXPECT_NEAR(law.slope(d), (law.slave(d + h) - law.slave(d - h)) / (2 * h), 1e-6) << "at " << d;
  EXPECT_NEAR(law.curvature(d), (law.slope(d + h) - law.slope(d - h)) / (2 * h), 1e-5) << "at " << d;
}

TEST(CouplingLaw, ConstantPitchIsATurnPerPitchBothWays) {
  const CouplingLaw right = CouplingLaw::constant(8.0);
  EXPECT_DOUBLE_EQ(right.slave(8.0), 360.0);
  EXPECT_DOUBLE_EQ(right.slave(-12.0), -540.0);
  EXPECT_DOUBLE_EQ(right.slope(3.0), 45.0);
  EXPECT_EQ(right.curvature(3.0), 0.0);
  const CouplingLaw left = CouplingLaw::constant(-8.0);  // left-hand helix
  EXPECT_DOUBLE_EQ(left.slave(8.0), -360.0);
  EXPECT_FALSE(CouplingLaw().active());
  EXPECT_EQ(CouplingLaw().slave(5.0), 0.0);
}

TEST(CouplingLaw, LinearPitchIsTheIntegralOfItsPitch) {
  for (const double rate : {0.02, -0.015, 0.0}) {
    const CouplingLaw law = CouplingLaw::linear(10.0, rate);
    for (const double d : {-150.0, -20.0, 0.0, 35.0, 200.0}) {
      EXPECT_NEAR(law.slave(d), integral_deg(law, d), 1e-7) << rate << " " << d;
      expect_derivatives(law, d);
    }
  }
  EXPECT_NEAR(CouplingLaw::linear(10.0, 1e-15).slave(100.0), 3600.0, 1e-9);  // k → 0 is the constant law
}

TEST(CouplingLaw, PitchTableIsTheIntegralOfItsPiecewisePitch) {
  const CouplingLaw law =
      CouplingLaw::tabulated(CouplingKind::PitchTable, table({{-50, 12}, {0, 10}, {80, 6}, {120, 6.5}}));
  EXPECT_EQ(law.slave(0.0), 0.0);
  for (const double d : {-80.0, -50.0, -10.0, 40.0, 80.0, 100.0, 150.0}) {
    EXPECT_NEAR(law.slave(d), integral_deg(law, d), 1e-6) << d;
  }
  for (const double d : {-70.0, -25.0, 40.0, 100.0, 140.0}) expect_derivatives(law, d);
  // Two points give the linear law.
  const CouplingLaw two = CouplingLaw::tabulated(CouplingKind::PitchTable, table({{0, 10}, {100, 12}}));
  EXPECT_NEAR(two.slave(60.0), CouplingLaw::linear(10.0, 0.02).slave(60.0), 1e-9);
}

TEST(CouplingLaw, CamPassesItsPointsAndIsC1) {
  const CouplingTable t = table({{0, 0}, {10, 30}, {25, 40}, {40, 100}, {60, 100}});
  const CouplingLaw cam = CouplingLaw::tabulated(CouplingKind::Cam, t);
  for (int i = 0; i < t.count; ++i) EXPECT_NEAR(cam.slave(t.master[i]), t.value[i], 1e-12);
  for (int i = 0; i < t.count; ++i) {
    const double m = t.master[i], h = 1e-7;
    const double left = (cam.slave(m) - cam.slave(m - h)) / h;
    const double right = (cam.slave(m + h) - cam.slave(m)) / h;
    EXPECT_NEAR(left, right, 1e-4) << "slope jumps at point " << i;
  }
  for (const double d : {-5.0, 5.0, 17.0, 33.0, 50.0, 70.0}) expect_derivatives(cam, d);
  // Engaged in the middle of the table: offsets from there.
  CouplingTable shifted = t;
  for (int i = 0; i < t.count; ++i) shifted.master[i] -= 25.0;
  const CouplingLaw mid = CouplingLaw::tabulated(CouplingKind::Cam, shifted);
  EXPECT_EQ(mid.slave(0.0), 0.0);
  EXPECT_NEAR(mid.slave(15.0), 60.0, 1e-12);
  EXPECT_NEAR(mid.slave(-25.0), -40.0, 1e-12);
}

TEST(CouplingLaw, ExtremesAreNeverBelowADenseSampling) {
  const CouplingLaw laws[] = {
      CouplingLaw::linear(10.0, -0.03),
      CouplingLaw::tabulated(CouplingKind::PitchTable, table({{0, 10}, {30, 4}, {60, 9}})),
      CouplingLaw::tabulated(CouplingKind::Cam, table({{0, 0}, {10, 30}, {25, 40}, {40, 100}, {60, 100}})),
  };
  for (const CouplingLaw& law : laws) {
    for (const auto& [a, b] : {std::pair{-5.0, 20.0}, std::pair{55.0, 12.0}, std::pair{0.0, 60.0}}) {
      double slope = 0, curv = 0;
      for (int i = 0; i <= 4000; ++i) {
        const double d = a + (b - a) * i / 4000.0;
        slope = std::max(slope, std::fabs(law.slope(d)));
        curv = std::max(curv, std::fabs(law.curvature(d)));
      }
      EXPECT_GE(law.max_slope(a, b), slope - 1e-9);
      EXPECT_LE(law.max_slope(a, b), slope * 1.001 + 1e-9);
      EXPECT_GE(law.max_curvature(a, b), curv - 1e-9);
    }
  }
}

TEST(CouplingLaw, ExtentFindsACamsOvershootBetweenPoints) {
  // Rises to 100 and back: the Hermite overshoots between the points; the extent finds it.
  const CouplingLaw cam =
      CouplingLaw::tabulated(CouplingKind::Cam, table({{0, 0}, {10, 100}, {20, 100}, {30, 0}}));
  double lo = 0, hi = 0;
  for (int i = 0; i <= 30000; ++i) {
    const double s = cam.slave(i * 1e-3);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  const auto [elo, ehi] = cam.slave_extent(0.0, 30.0);
  EXPECT_NEAR(elo, lo, 1e-6);
  EXPECT_NEAR(ehi, hi, 1e-6);
  EXPECT_GT(ehi, 100.0);
  const auto [plo, phi] = CouplingLaw::constant(5.0).slave_extent(10.0, -5.0);
  EXPECT_DOUBLE_EQ(plo, -360.0);
  EXPECT_DOUBLE_EQ(phi, 720.0);
}

TEST(CouplingLaw, ACodesLawComesFromItsKindAndTheMachinesTables) {
  CouplingConfig config;
  config.enabled = true;
  config.table_kind[0] = CouplingKind::PitchTable;
  config.tables[0] = table({{0, 10}, {100, 12}});
  config.table_kind[2] = CouplingKind::Cam;
  config.tables[2] = table({{0, 0}, {10, 30}, {20, 40}});
  EXPECT_DOUBLE_EQ(law_for(config, CouplingKind::ConstantPitch, 8, 0, 0).slave(4), 180);
  EXPECT_DOUBLE_EQ(law_for(config, CouplingKind::LinearPitch, 10, 0.02, 0).slave(60),
                   CouplingLaw::linear(10, 0.02).slave(60));
  EXPECT_DOUBLE_EQ(law_for(config, CouplingKind::PitchTable, 0, 0, 1).slave(60),
                   CouplingLaw::tabulated(CouplingKind::PitchTable, config.tables[0]).slave(60));
  EXPECT_EQ(law_for(config, CouplingKind::Cam, 0, 0, 3).kind(), CouplingKind::Cam);
  // What the machine does not have is no law: a missing table, a table of the other kind, Off.
  EXPECT_FALSE(law_for(config, CouplingKind::PitchTable, 0, 0, 2).active());
  EXPECT_FALSE(law_for(config, CouplingKind::Cam, 0, 0, 1).active());
  EXPECT_FALSE(law_for(config, CouplingKind::PitchTable, 0, 0, 0).active());
  EXPECT_FALSE(law_for(config, CouplingKind::PitchTable, 0, 0, kMaxCouplingTables + 1).active());
  EXPECT_FALSE(law_for(config, CouplingKind::Off, 8, 0, 0).active());
}

}  // namespace
}  // namespace opencnc::motion
