// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated spark gap: open / normal / short by the gap's width, the mean voltage rising with
// the gap, removal that deepens the front, debris that turns discharges into arcs unless a lift
// flushes it, an injected short that holds until the electrode backs off, a front per orientation.
#include <gtest/gtest.h>

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
    p.step(z, orientation, on, roughing(), rng);
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

}  // namespace
}  // namespace opencnc::machine
