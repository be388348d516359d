// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated plate and arc on their own: the warped surface, the voltage from height, speed
// and kerfs, arc-OK after its delay, losses, the float switch.
#include <gtest/gtest.h>

#include <cmath>

#include "opencnc/machine/sim_plasma_process.hpp"

namespace opencnc::machine {
namespace {

SimPlasmaConfig plate(std::uint64_t seed = 7) {
  SimPlasmaConfig c;
  c.present = true;
  c.seed = seed;
  c.warp_mm = 5;
  c.plate_max[0] = 600;
  c.plate_max[1] = 600;
  c.noise_v = 0;
  return c;
}

TEST(SimPlasma, ThePlateIsASmoothWarpWithinItsAmplitudeAndTheSameForASeed) {
  const PlateSurface s(plate()), same(plate()), other(plate(8));
  double lo = 1e9, hi = -1e9, steepest = 0, differs = 0;
  for (double x = 0; x <= 1200; x += 5) {
    for (double y = 0; y <= 2400; y += 5) {
      const double z = s.z(x, y);
      lo = std::min(lo, z);
      hi = std::max(hi, z);
      steepest = std::max(steepest, std::fabs(s.z(x + 1, y) - z));
      EXPECT_EQ(z, same.z(x, y));
      differs = std::max(differs, std::fabs(z - other.z(x, y)));
    }
  }
  EXPECT_GE(lo, -5.0);
  EXPECT_LE(hi, 5.0);
  EXPECT_GT(hi - lo, 5.0) << "warped by several mm over the sheet";
  EXPECT_LT(steepest, 0.05) << "smooth: under 0.05 mm per mm";
  EXPECT_GT(differs, 1.0);
}

TEST(SimPlasma, TheArcComesAfterItsDelayAndItsVoltageGrowsWithHeightAndAKerf) {
  SimPlasmaProcess p;
  p.configure(plate(), 1e-3);
  const double top = p.surface().z(100, 100);
  MachineInputs in;
  int periods = 0;
  while (!p.arc() && periods < 1000) {
    p.step(100, 100, top + 3.8, true);
    ++periods;
  }
  EXPECT_NEAR(periods * 1e-3, plate().arc_delay_s, 1.5e-3);
  p.sample(in);
  EXPECT_TRUE(in.process.arc_ok);
  const double at_rest = in.analog_in[0];
  EXPECT_NEAR(at_rest, 100 + 7.5 * 3.8 + 6, 1e-9);  // at a standstill: slow_volts more
  // Cutting along X at full speed, 1.5 mm above the plate: then back across the kerf along Y.
  double x = 100;
  for (int i = 0; i < 2000; ++i) {
    x += 0.04;
    p.step(x, 100, p.surface().z(x, 100) + 1.5, true);
  }
  p.sample(in);
  EXPECT_NEAR(in.analog_in[0], 100 + 7.5 * 1.5, 0.01);
  EXPECT_TRUE(p.kerf_at(120, 100));
  EXPECT_FALSE(p.kerf_at(120, 103));
  p.step(x, 100, p.surface().z(x, 100) + 1.5, false);  // torch off: the arc goes out
  EXPECT_FALSE(p.arc());
  double y = 90, most = 0;
  while (!p.arc()) p.step(120, y, p.surface().z(120, y) + 3.8, true);
  for (int i = 0; i < 500; ++i) {
    y += 0.04;
    p.step(120, y, p.surface().z(120, y) + 1.5, true);
    p.sample(in);
    most = std::max(most, in.analog_in[0]);
  }
  EXPECT_NEAR(most, 100 + 7.5 * 1.5 + 25, 0.5) << "crossing the kerf cut along X";
}

TEST(SimPlasma, AnInjectedLossLastsUntilTheTorchIsSwitchedAgainAndTheFloatSwitchTripsBelowThePlate) {
  SimPlasmaProcess p;
  p.configure(plate(), 1e-3);
  const double top = p.surface().z(50, 50);
  MachineInputs in;
  p.step(50, 50, top - 1.47, false);
  p.sample(in);
  EXPECT_FALSE(in.digital_in & 1u);
  p.step(50, 50, top - 1.53, false);
  p.sample(in);
  EXPECT_TRUE(in.digital_in & 1u);
  for (int i = 0; i < 400; ++i) p.step(50, 50, top + 1.5, true);
  ASSERT_TRUE(p.arc());
  p.inject_arc_loss();
  p.step(50, 50, top + 1.5, true);
  EXPECT_FALSE(p.arc());
  EXPECT_EQ(p.arc_losses(), 1u);
  for (int i = 0; i < 400; ++i) p.step(50, 50, top + 1.5, true);
  EXPECT_FALSE(p.arc()) << "out until the torch is switched off";
  p.step(50, 50, top + 1.5, false);
  for (int i = 0; i < 400; ++i) p.step(50, 50, top + 1.5, true);
  EXPECT_TRUE(p.arc());
}

}  // namespace
}  // namespace opencnc::machine
