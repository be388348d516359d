// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated spark gap: open / normal / short by the gap's width, the mean voltage rising with
// the gap, removal that deepens the front, debris that turns discharges into arcs unless a lift
// flushes it, an injected short that holds until the electrode backs off, a front per orientation,
// side walls burnt out to the orbit plus the side gap, the electrode's wear by the condition's ratio.
#include <gtest/gtest.h>

#include <cmath>

#include "opencnc/machine/sim_edm_process.hpp"

namespace opencnc::machine {
namespace {

GeneratorOutputs roughing() {
  GeneratorOutputs g;
  g.on_time_us = 100;
  g.off_time_us = 50;
  g.peak_current_a = 12;
  g.voltage_v = 100;
  return g;
}

struct Gap {
  SimEdmProcess p;
  SplitMix64 rng{7};
  double orientation[2] = {0, 0};
  Gap() {
    SimEdmConfig c;
    c.present = true;
    c.surface_mm = 0;  // the work below Z 0
    c.noise_v = 0;
    p.configure(c, 0.001);
  }
  ProcessInputs at(double z, bool on = true) {
    SimEdmPose pose;
    pose.feed = z;
    pose.orientation[0] = orientation[0];
    pose.orientation[1] = orientation[1];
    p.step(pose, on, roughing(), rng);
    ProcessInputs in;
    p.sample(in);
    return in;
  }
};

TEST(SimEdmProcess, StateAndVoltageFollowTheGap) {
  Gap g;
  EXPECT_EQ(g.at(0.05).gap_state, GapState::Open);  // breakdown gap 0.3 µm/V × 100 V = 30 µm
  EXPECT_EQ(g.at(0.05).gap_voltage_v, 100.0);
  EXPECT_EQ(g.at(-0.001).gap_state, GapState::Short);
  EXPECT_LT(g.at(-0.001).gap_voltage_v, 2.0);
  // Within the breakdown gap the mean voltage rises with the gap.
  double last = 0;
  for (double z : {0.004, 0.008, 0.012, 0.016, 0.020}) {
    Gap fresh;
    const ProcessInputs in = fresh.at(z);
    EXPECT_EQ(in.gap_state, GapState::Normal);
    EXPECT_GT(in.gap_voltage_v, last);
    last = in.gap_voltage_v;
  }
  EXPECT_EQ(g.at(0.05, false).gap_voltage_v, 0.0);  // generator off
}

TEST(SimEdmProcess, DischargesRemoveMaterialAndLeaveDebris) {
  Gap g;
  for (int i = 0; i < 100; ++i) g.at(0.012);
  EXPECT_GT(g.p.depth_mm(), 0.0005);  // ~12 µm/s at 12 A, 100 µs, on 20 mm²
  EXPECT_LT(g.p.depth_mm(), 0.003);
  EXPECT_GT(g.p.debris(), 0.0);
  EXPECT_GT(g.p.discharges(), 100u);
}

TEST(SimEdmProcess, DebrisTurnsDischargesToArcsUnlessALiftFlushesIt) {
  Gap g;
  int arcs = 0;
  for (int i = 0; i < 3000; ++i) {
    // Hold a narrow gap as a servo would: the electrode follows the front down.
    const double z = -g.p.depth_mm() + 0.010;
    arcs += g.at(z).gap_state == GapState::Arc;
  }
  EXPECT_GT(g.p.debris(), 0.35);
  EXPECT_GT(arcs, 100);
  const double before = g.p.debris();
  for (int i = 0; i < 50; ++i) g.at(1.0, false);  // lifted 1 mm, the generator off
  EXPECT_LT(g.p.debris(), 0.2 * before);
}

TEST(SimEdmProcess, AnInjectedShortHoldsUntilTheElectrodeBacksOff) {
  Gap g;
  g.at(0.012);
  g.p.inject_short();
  EXPECT_EQ(g.at(0.012).gap_state, GapState::Short);
  EXPECT_EQ(g.at(0.025).gap_state, GapState::Short);  // 13 µm back: the 20 µm bridge holds
  EXPECT_NE(g.at(0.035).gap_state, GapState::Short);  // 23 µm back: broken
}

TEST(SimEdmProcess, EachOrientationHasItsOwnFront) {
  Gap g;
  for (int i = 0; i < 200; ++i) g.at(0.010);
  const double left = g.p.depth_mm();
  g.orientation[0] = 30;
  g.at(0.05);
  EXPECT_EQ(g.p.depth_mm(), 0.0);
  g.orientation[0] = 0;
  g.at(0.05);
  EXPECT_NEAR(g.p.depth_mm(), left, 1e-12);
}

TEST(SimEdmProcess, TurningTheWorkWithTheGeneratorOffKeepsItsFronts) {
  Gap g;
  for (int i = 0; i < 200; ++i) g.at(0.010);
  const double first = g.p.depth_mm();
  for (int b = 0; b >= -30; --b) {  // B through thirty whole degrees under G0: no front for each
    g.orientation[0] = b;
    g.at(1.0, false);
    if (b < 0) {
      EXPECT_EQ(g.p.depth_mm(), 0.0);
    }
  }
  for (int i = 0; i < 200; ++i) g.at(0.010);  // the second flank
  for (int b = -30; b <= 0; ++b) {
    g.orientation[0] = b;
    g.at(1.0, false);
  }
  EXPECT_NEAR(g.p.depth_mm(), first, 1e-12);  // the first flank's front is still there
  EXPECT_GE(g.p.depth_max_mm(), first);
}

/// A gap with side walls in X/Y and two conditions: 2 (side gap 20 µm, 10 % wear) and 3 (none given).
struct Cavity {
  SimEdmProcess p;
  SplitMix64 rng{11};
  SimEdmPose pose;
  GeneratorOutputs gen = roughing();
  Cavity() {
    SimEdmConfig c;
    c.present = true;
    c.surface_mm = 0;
    c.noise_v = 0;
    c.removal_mm3_per_a_us = 5e-7;  // ten times the default: the test burns in tenths of a second
    c.debris_per_mm3 = 0;           // no arcs: the walls and the wear alone
    c.lateral_joints[0] = 0;
    c.lateral_joints[1] = 1;
    c.conditions[0] = {2, 0.020, 0.1};
    c.conditions[1] = {3, 0.0, 0.0};
    c.condition_count = 2;
    p.configure(c, 0.001);
    gen.condition = 2;
    pose.lateral[0] = 5;  // the burn's centre: X 5, Y −3
    pose.lateral[1] = -3;
  }
  /// One period with the electrode's tip held `gap_mm` off the front, as the gap servo would.
  void hold(double gap_mm) {
    pose.feed = -p.depth_mm() + gap_mm - p.electrode_wear_mm();
    p.step(pose, true, gen, rng);
  }
};

TEST(SimEdmProcess, TheSideWallsStandTheSideGapBeyondTheElectrode) {
  Cavity c;
  for (int i = 0; i < 400; ++i) c.hold(0.010);
  ASSERT_GT(c.p.depth_mm(), 0.05);  // the tip well inside the work
  for (int k = 0; k < SimEdmProcess::kSides; ++k) EXPECT_DOUBLE_EQ(c.p.side_wall_mm(k), 0.020);
  EXPECT_DOUBLE_EQ(c.p.cavity_oversize_mm(), 0.020);
  c.gen.condition = 3;  // no side gap in the table: the clean breakdown gap, 0.3 µm/V × 100 V
  c.hold(0.010);
  EXPECT_NEAR(c.p.side_gap_mm(), 0.030, 1e-12);
  EXPECT_NEAR(c.p.cavity_oversize_mm(), 0.030, 1e-12);
}

TEST(SimEdmProcess, AnOrbitWidensTheCavityByItsRadiusPlusTheSideGap) {
  Cavity c;
  for (int i = 0; i < 400; ++i) c.hold(0.010);
  const double r = 0.05;
  for (int i = 0; i <= 1000; ++i) {  // one turn of a 50 µm circle around the centre
    const double a = 2 * 3.14159265358979323846 * i / 1000;
    c.pose.lateral[0] = 5 + r * std::cos(a);
    c.pose.lateral[1] = -3 + r * std::sin(a);
    c.hold(0.010);
  }
  // Within the sampling of the turn (0.36° a period: r·(1 − cos 0.18°) = 0.25 nm).
  for (int k = 0; k < SimEdmProcess::kSides; ++k) EXPECT_NEAR(c.p.side_wall_mm(k), r + 0.020, 1e-6) << k;
  EXPECT_NEAR(c.p.cavity_oversize_mm(), r + 0.020, 1e-6);
  // A move 0.1 mm along +X only widens the walls that face +X.
  c.pose.lateral[0] = 5.1;
  c.pose.lateral[1] = -3;
  c.hold(0.010);
  EXPECT_NEAR(c.p.side_wall_mm(0), 0.120, 1e-12);
  EXPECT_NEAR(c.p.side_wall_mm(SimEdmProcess::kSides / 2), r + 0.020, 1e-6);
  EXPECT_NEAR(c.p.cavity_oversize_max_mm(), c.p.cavity_oversize_mm(), 1e-15);
}

TEST(SimEdmProcess, NoSideWallAboveTheSurfaceOrWithoutABurn) {
  Cavity c;
  c.pose.lateral[0] = 5.5;
  c.pose.feed = 1.0;  // open gap, far above
  c.p.step(c.pose, true, c.gen, c.rng);
  EXPECT_EQ(c.p.cavity_oversize_mm(), 0.0);
  c.hold(0.010);  // the first discharge sets the centre; the tip is still above the surface
  EXPECT_EQ(c.p.cavity_oversize_mm(), 0.0);
}

TEST(SimEdmProcess, TheElectrodeWearsByTheConditionsRatio) {
  Cavity c;
  for (int i = 0; i < 400; ++i) c.hold(0.010);
  const double depth = c.p.depth_mm();
  ASSERT_GT(depth, 0.05);
  EXPECT_NEAR(c.p.electrode_wear_mm(), 0.1 * depth, 1e-12);
  // To keep the gap, the feed joint went the wear further than the front (within the last
  // period's removal, 0.17 µm).
  EXPECT_NEAR(c.pose.feed, -depth + 0.010 - 0.1 * depth, 5e-4);
  EXPECT_LT(c.pose.feed, -depth + 0.010 - 0.09 * depth);
  c.gen.condition = 3;  // no wear given: none
  const double worn = c.p.electrode_wear_mm();
  for (int i = 0; i < 100; ++i) c.hold(0.010);
  EXPECT_EQ(c.p.electrode_wear_mm(), worn);
  // A new electrode starts unworn; the first one keeps its wear when it comes back.
  c.p.mount(7);
  EXPECT_EQ(c.p.electrode_wear_mm(), 0.0);
  c.p.mount(0);
  EXPECT_EQ(c.p.electrode_wear_mm(), worn);
  EXPECT_EQ(c.p.electrode_wear_max_mm(), worn);
  c.p.replace(0);  // a new electrode for tool 0: its wear starts again
  EXPECT_EQ(c.p.electrode_wear_mm(), 0.0);
}

TEST(SimEdmProcess, WithARemovalRateASideWallRecedesByItsDischargesAndLoadsTheGap) {
  // The walls burn by the side discharges: condition 2's side gap of 20 µm is the widest side
  // distance that sparks here (no reference given), the electrode's outline 16 mm.
  Cavity c;
  SimEdmConfig cfg;
  cfg.present = true;
  cfg.surface_mm = 0;
  cfg.noise_v = 0;
  cfg.debris_per_mm3 = 0;  // the default removal: a wall recedes by less than its room in a period
  cfg.lateral_joints[0] = 0;
  cfg.lateral_joints[1] = 1;
  cfg.conditions[0] = {2, 0.020, 0.0, 0.0};
  cfg.condition_count = 1;
  cfg.side_walls = SideWalls::Removal;
  cfg.electrode_perimeter_mm = 16;
  c.p.configure(cfg, 0.001);
  for (int i = 0; i < 4000; ++i) c.hold(0.010);
  ASSERT_GT(c.p.depth_mm(), 0.05);
  // Sinking without a lateral move the front's discharges at the edge leave the mouth the frontal
  // gap (10 µm) wide all round; the sides (x = 10/20) are wider than the front (10/30): no side burns.
  for (int k = 0; k < SimEdmProcess::kSides; ++k) EXPECT_NEAR(c.p.side_wall_mm(k), 0.010, 1e-12) << k;
  // 6 µm along +X: the wall facing +X stands 4 µm off (x = 0.2), nearer than the front (x = 1/3):
  // the period's discharges go there, at that gap's voltage, and it recedes by their volume over
  // its area (16 mm / 32 × the depth), not at once.
  c.pose.lateral[0] = 5.006;
  const double depth = c.p.depth_mm();
  c.hold(0.010);
  ProcessInputs in;
  c.p.sample(in);
  EXPECT_EQ(in.gap_state, GapState::Normal);
  const double x = 0.004 / 0.020, ton = 100, toff = 50, td = ton * x / (1 - x);
  EXPECT_NEAR(in.gap_voltage_v, (100 * td + 25 * ton) / (td + ton + toff), 1e-9);
  const double volume = 1000 / (td + ton + toff) * 5e-8 * 12 * ton;
  EXPECT_NEAR(c.p.side_wall_mm(0) - 0.010, volume / (16.0 / 32 * depth), 1e-12);
  EXPECT_NEAR(c.p.depth_mm(), depth, 1e-15) << "the front did not burn this period";
  EXPECT_NEAR(c.p.side_wall_mm(SimEdmProcess::kSides / 2), 0.010, 1e-12);
  // Held there with the front out of reach, the wall burns out to the side gap beyond the
  // outline and no further; then the gap is open.
  for (int i = 0; i < 2000; ++i) c.hold(0.040);
  EXPECT_NEAR(c.p.side_wall_mm(0), 0.006 + 0.020, 1e-6);
  c.p.sample(in);
  EXPECT_EQ(in.gap_state, GapState::Open);
}

TEST(SimEdmProcess, DebrisAboveItsThresholdBridgesTheGapIntoShorts) {
  // No jump: the debris of a steady burn passes short_debris, and bridges short the gap now and
  // then; each holds until the electrode has backed off half a breakdown gap.
  auto shorts_with = [](double short_debris) {
    Cavity c;
    SimEdmConfig cfg;
    cfg.present = true;
    cfg.surface_mm = 0;
    cfg.noise_v = 0;
    cfg.side_walls = SideWalls::Removal;
    cfg.short_debris = short_debris;
    cfg.arc_threshold = 0.99;  // debris makes no arcs here: the shorts alone
    c.p.configure(cfg, 0.001);
    int n = 0;
    for (int i = 0; i < 5000; ++i) {
      c.hold(0.010);
      ProcessInputs in;
      c.p.sample(in);
      n += in.gap_state == GapState::Short ? 1 : 0;
    }
    return std::pair{n, c.p.debris()};
  };
  const auto [none, debris] = shorts_with(0);
  EXPECT_EQ(none, 0);
  ASSERT_GT(debris, 0.2);
  const auto [some, debris_too] = shorts_with(0.5 * debris);
  EXPECT_GT(some, 0);
}

}  // namespace
}  // namespace opencnc::machine
