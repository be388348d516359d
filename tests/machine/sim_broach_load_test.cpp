// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated broaching load: the chip a stroke meets, the force from it, a worn cutter, the
// material other strokes left, and the load cell on the machine's analog input.
#include <gtest/gtest.h>

#include <cmath>

#include "opencnc/machine/sim_broach_load.hpp"

namespace opencnc::machine {
namespace {

SimBroachConfig bore() {
  SimBroachConfig c;
  c.present = true;
  c.bore_start = 0;
  c.bore_end = 600;
  c.surface = 0;
  c.specific_force_n_mm2 = 2500;
  c.width_mm = 10;
  c.speed_gain_per_m_min = 0.05;
  c.noise_kn = 0.02;
  c.radius_mm = 40;
  return c;
}

/// One stroke along the helix C = 360·z/600 + c0 at 50 mm/s with the cutter at `radial`, from z0
/// to z1 in 1 ms periods; returns the largest and the mean load met inside the bore.
struct Stroke {
  double max_kn = -1e9, mean_kn = 0;
};
Stroke stroke(SimBroachLoad& m, double radial, double c0 = 0, double z0 = -10, double z1 = 300) {
  const double v = z1 > z0 ? 50.0 : -50.0;
  Stroke s;
  int n = 0;
  for (double z = z0; (v > 0 ? z <= z1 : z >= z1); z += v * 0.001) {
    m.update(z, v, c0 + 360 * z / 600, radial);
    if (z > 5 && z < 295) {
      s.max_kn = std::max(s.max_kn, m.load_kn());
      s.mean_kn += m.load_kn();
      ++n;
    }
  }
  s.mean_kn /= n;
  return s;
}

TEST(SimBroachLoad, AStrokeMeetsTheChipOfItsInfeed) {
  SimBroachLoad m(bore(), 1);
  // 2500 N/mm² × 10 mm × 0.1 mm × (1 + 0.05 × 3 m/min) = 2875 N.
  const Stroke first = stroke(m, 0.1);
  EXPECT_NEAR(first.mean_kn, 2.875, 0.005);
  EXPECT_LE(first.max_kn, 2.875 + 0.02);
  // The same depth again along the same helix: nothing left to cut, the cell reads its noise.
  const Stroke again = stroke(m, 0.1);
  EXPECT_LT(std::fabs(again.mean_kn), 0.005);
  EXPECT_LE(again.max_kn, 0.02);
  // The next infeed: the next 0.1 mm.
  EXPECT_NEAR(stroke(m, 0.2).mean_kn, 2.875, 0.005);
  EXPECT_NEAR(m.cut_depth(100, 60), 0.2, 1e-6);
}

// A simulation powered up again takes over the workpiece: a stroke that carries on from rest where
// the first stopped (z 140, inside the cell [138.28, 140.63)) meets nothing before the next cell
// and the infeed's chip from there on.
TEST(SimBroachLoad, ARestoredBoreKeepsItsGroove) {
  SimBroachLoad first(bore(), 1);
  stroke(first, 0.1, 0, -10, 140);
  SimBroachLoad again(bore(), 2);
  EXPECT_FALSE(again.restore_bore(first.bore().first(10)));  // another geometry: nothing changed
  EXPECT_EQ(again.cut_depth(100, 60), 0.0);
  ASSERT_TRUE(again.restore_bore(first.bore()));
  EXPECT_NEAR(again.cut_depth(100, 60), 0.1, 1e-6);
  const double next_cell = 600.0 / SimBroachLoad::kStrokeCells * 60;
  double before = 0, beyond = 0;
  for (double z = 140; z <= 300; z += 0.05) {
    again.update(z, z == 140 ? 0 : 50, 360 * z / 600, 0.1);
    double& worst = z < next_cell ? before : beyond;
    worst = std::max(worst, again.chip_mm());
  }
  EXPECT_EQ(before, 0.0);          // the groove cut before the stop
  EXPECT_NEAR(beyond, 0.1, 1e-6);  // fresh material past it
}

TEST(SimBroachLoad, TheSecondGrooveIsFreshMaterialAndTheReturnCutsNothing) {
  SimBroachLoad m(bore(), 1);
  stroke(m, 0.1);
  EXPECT_NEAR(stroke(m, 0.1, 180).mean_kn, 2.875, 0.005);  // C indexed half a turn
  // Back the way it came with the cutter still in the groove: what it cut, it cuts again not.
  EXPECT_LT(std::fabs(stroke(m, 0.1, 0, 300, -10).mean_kn), 0.005);
}

TEST(SimBroachLoad, AWornCutterPullsHarderAndNothingCutsAtRestOrOutside) {
  SimBroachLoad m(bore(), 1);
  m.set_dull_factor(2.0);
  EXPECT_NEAR(stroke(m, 0.1).mean_kn, 5.75, 0.01);
  SimBroachLoad rest(bore(), 1);
  rest.update(100, 0, 60, 0.3);  // at rest in the bore
  EXPECT_LE(std::fabs(rest.load_kn()), 0.02);
  rest.update(-5, 50, 0, 0.3);  // moving, outside the bore
  EXPECT_LE(std::fabs(rest.load_kn()), 0.02);
  EXPECT_EQ(rest.stroke_force_n(), 0.0);
}

TEST(SimBroachLoad, TheForceResistsTheStrokeAndTheNoiseIsSeeded) {
  SimBroachLoad a(bore(), 7), b(bore(), 7), c(bore(), 8);
  double differs = 0;
  for (int i = 0; i < 200; ++i) {
    const double z = 10 + 0.05 * i;
    a.update(z, 50, 6 * z / 10, 0.1);
    b.update(z, 50, 6 * z / 10, 0.1);
    c.update(z, 50, 6 * z / 10, 0.1);
    ASSERT_EQ(a.load_kn(), b.load_kn());
    differs += std::fabs(a.load_kn() - c.load_kn());
    EXPECT_LT(a.stroke_force_n(), 0.0);  // against +Z
  }
  EXPECT_GT(differs, 0.0);
}

}  // namespace
}  // namespace opencnc::machine
