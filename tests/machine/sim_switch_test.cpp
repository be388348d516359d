// SPDX-License-Identifier: GPL-3.0-or-later
// SimSwitch edges with hysteresis and noise; the seeded generator.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::machine {
namespace {

TEST(SplitMix64, MatchesTheReferenceSequence) {
  // First outputs of the published algorithm for seed 0.
  SplitMix64 rng(0);
  EXPECT_EQ(rng.next(), 0xE220A8397B1DCDAFull);
  EXPECT_EQ(rng.next(), 0x6E789E6AA1B965F4ull);
}

TEST(SplitMix64, SymmetricStaysInRangeAndIsCentred) {
  SplitMix64 rng(3);
  double sum = 0;
  for (int i = 0; i < 100000; ++i) {
    const double u = rng.symmetric();
    ASSERT_GE(u, -1.0);
    ASSERT_LT(u, 1.0);
    sum += u;
  }
  EXPECT_NEAR(sum / 100000, 0.0, 0.01);
}

/// Positions where the switch changes state while the position sweeps through `path`.
std::vector<double> edges(SimSwitch& sw, const std::vector<double>& path, SplitMix64& rng) {
  std::vector<double> out;
  bool state = sw.active();
  for (double x : path) {
    if (sw.update(x, rng) != state) {
      state = !state;
      out.push_back(x);
    }
  }
  return out;
}

std::vector<double> sweep(double from, double to, double step) {
  std::vector<double> p;
  const int n = static_cast<int>(std::abs(to - from) / step + 0.5);
  for (int i = 0; i <= n; ++i) p.push_back(from + (to - from) * i / n);
  return p;
}

TEST(SimSwitch, HysteresisMovesTheReleasePoint) {
  SimSwitch home({true, 10.0, kInf}, 0.05, 0.0);
  SplitMix64 rng(1);
  auto e = edges(home, sweep(9.0, 11.0, 0.001), rng);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NEAR(e[0], 10.0, 1e-9);
  e = edges(home, sweep(11.0, 9.0, 0.001), rng);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NEAR(e[0], 10.0 - 0.05 - 0.001, 1e-9);  // first sample below 9.95
}

TEST(SimSwitch, WindowHasTwoEdges) {
  SimSwitch dog({true, 100.0, 120.0}, 0.0, 0.0);
  SplitMix64 rng(1);
  auto e = edges(dog, sweep(90, 130, 0.01), rng);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NEAR(e[0], 100.0, 1e-9);
  EXPECT_NEAR(e[1], 120.01, 1e-9);
}

// Noise smaller than half the hysteresis jitters the edges but never makes a switch chatter;
// each edge lies within ±noise of its nominal point.
TEST(SimSwitch, NoiseJittersEdgesWithoutChatter) {
  SplitMix64 rng(99);
  const double noise = 0.004, hyst = 0.01;
  double lowest = 1e9, highest = -1e9;
  for (int run = 0; run < 200; ++run) {
    SimSwitch sw({true, -kInf, -5.0}, hyst, noise);
    auto e = edges(sw, sweep(0, -6, 0.0005), rng);
    ASSERT_EQ(e.size(), 1u);
    lowest = std::min(lowest, e[0]);
    highest = std::max(highest, e[0]);
    auto back = edges(sw, sweep(-6, 0, 0.0005), rng);
    ASSERT_EQ(back.size(), 1u);
    EXPECT_GE(back[0], -5.0 + hyst - noise);
    EXPECT_LE(back[0], -5.0 + hyst + noise + 0.0005);
  }
  EXPECT_GE(lowest, -5.0 - noise - 0.0005);
  EXPECT_LE(highest, -5.0 + noise);
  EXPECT_GT(highest - lowest, noise);  // the noise is really there
}

TEST(SimSwitch, AbsentSwitchNeverTrips) {
  SimSwitch none;
  SplitMix64 rng(1);
  EXPECT_FALSE(none.update(0.0, rng));
  EXPECT_FALSE(none.present());
}

}  // namespace
}  // namespace opencnc::machine
