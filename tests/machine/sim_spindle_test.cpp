// SPDX-License-Identifier: GPL-3.0-or-later
// SimSpindle: acceleration-limited ramp, at-speed, encoder quantisation and index, orient.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "opencnc/machine/sim_spindle.hpp"

namespace opencnc::machine {
namespace {

constexpr double kPeriod = 0.001;
constexpr int kSubsteps = 10;

SimSpindleConfig spindle_config() {
  SimSpindleConfig c;
  c.max_rpm = 6000;
  c.acceleration_rpm_s = 1000;
  c.encoder_counts_per_rev = 1024;
  return c;
}

struct SpindleRig {
  SimSpindle spindle;
  SpindleInputs in{};
  explicit SpindleRig(const SimSpindleConfig& c) : spindle(c, kPeriod, kSubsteps) {}
  void run(const SpindleOutputs& cmd, int periods, bool powered = true) {
    for (int k = 0; k < periods; ++k) {
      spindle.begin_period(cmd, powered);
      for (int i = 0; i < kSubsteps; ++i) spindle.substep();
      spindle.end_period();
      spindle.sample(in);
    }
  }
};

TEST(SimSpindle, RampsAtTheAccelerationLimit) {
  SpindleRig rig(spindle_config());
  SpindleOutputs cmd{3000, SpindleDirection::Clockwise};
  rig.run(cmd, 1000);
  EXPECT_NEAR(rig.in.speed_rpm, 1000, 1e-6);
  EXPECT_FALSE(rig.in.at_speed);
  // Position after 1 s of constant acceleration: ½·a·t² with a = 1000/60 rev/s².
  EXPECT_NEAR(rig.spindle.position_rev(), 0.5 * 1000.0 / 60.0, 1e-6);
  rig.run(cmd, 2000);
  EXPECT_NEAR(rig.in.speed_rpm, 3000, 1e-6);
  EXPECT_TRUE(rig.in.at_speed);
}

// The drive's torque: I·α while ramping plus friction (Coulomb and viscous) and the load against
// the turning; signed like the speed; nothing without power or at rest.
TEST(SimSpindle, TorqueIsInertiaFrictionAndLoadAgainstTheTurning) {
  SimSpindleConfig c = spindle_config();
  c.inertia_kgm2 = 0.02;
  c.friction_nm = 0.4;
  c.viscous_nm_per_krpm = 0.1;
  constexpr double kTwoPi = 6.283185307179586;
  const double alpha = kTwoPi * c.acceleration_rpm_s / 60.0;  // rad/s²
  SpindleRig rig(c);
  rig.run({}, 10);
  EXPECT_EQ(rig.in.torque_nm, 0.0);
  rig.run({3000, SpindleDirection::Clockwise}, 1000);  // 1000 rpm, still ramping
  EXPECT_NEAR(rig.in.torque_nm, 0.02 * alpha + 0.4 + 0.1 * 1.0, 1e-9);
  rig.run({3000, SpindleDirection::Clockwise}, 3000);  // at 3000 rpm
  EXPECT_NEAR(rig.in.torque_nm, 0.4 + 0.1 * 3.0, 1e-9);
  rig.spindle.set_load(5.0);
  rig.run({3000, SpindleDirection::Clockwise}, 1);
  EXPECT_NEAR(rig.in.torque_nm, 5.0 + 0.4 + 0.3, 1e-9);
  rig.spindle.set_load(0);
  rig.run({0, SpindleDirection::Stopped}, 1000);  // braking from 3000 to 2000 rpm: the drive holds back
  EXPECT_NEAR(rig.in.torque_nm, -0.02 * alpha + 0.4 + 0.1 * 2.0, 1e-9);
  rig.run({3000, SpindleDirection::Counterclockwise}, 10000);
  EXPECT_NEAR(rig.in.torque_nm, -(0.4 + 0.3), 1e-9);
  rig.run({3000, SpindleDirection::Counterclockwise}, 1, /*powered=*/false);
  EXPECT_EQ(rig.in.torque_nm, 0.0);
}

TEST(SimSpindle, CommandIsClampedToMaximumSpeed) {
  SpindleRig rig(spindle_config());
  rig.run({9000, SpindleDirection::Counterclockwise}, 7000);
  EXPECT_NEAR(rig.in.speed_rpm, -6000, 1e-6);
}

TEST(SimSpindle, EncoderIsQuantisedAndIndexCountsTurns) {
  SpindleRig rig(spindle_config());
  rig.run({600, SpindleDirection::Clockwise}, 5000);  // 0.6 s ramp, then 10 rev/s
  const double turns = rig.spindle.position_rev();
  EXPECT_EQ(rig.in.index_count, static_cast<std::uint32_t>(std::floor(turns)));
  EXPECT_EQ(rig.in.index_position_rev, std::floor(turns));
  EXPECT_EQ(rig.in.position_rev * 1024, std::floor(turns * 1024));
  // Reverse: the spindle runs on while it brakes, then back; every mark passed counts.
  const std::uint32_t before = rig.in.index_count;
  double farthest = turns;
  for (int k = 0; k < 3000; ++k) {
    rig.run({600, SpindleDirection::Counterclockwise}, 1);
    farthest = std::max(farthest, rig.spindle.position_rev());
  }
  const double end = rig.spindle.position_rev();
  EXPECT_LT(end, turns);
  EXPECT_EQ(rig.in.index_count - before,
            static_cast<std::uint32_t>((std::floor(farthest) - std::floor(turns)) +
                                       (std::floor(farthest) - std::floor(end))));
  EXPECT_EQ(rig.in.index_position_rev, std::floor(end) + 1);
}

TEST(SimSpindle, OrientStopsAtTheAngle) {
  SpindleRig rig(spindle_config());
  rig.run({1200, SpindleDirection::Clockwise}, 1500);
  SpindleOutputs orient{1200, SpindleDirection::Clockwise, true, 90.0};
  rig.run(orient, 5000);
  EXPECT_TRUE(rig.in.orient_done);
  const double angle = 360.0 * (rig.spindle.position_rev() - std::floor(rig.spindle.position_rev()));
  EXPECT_NEAR(angle, 90.0, 0.5);
  EXPECT_NEAR(rig.in.speed_rpm, 0.0, 1.0);
}

TEST(SimSpindle, UnpoweredSpindleRunsDown) {
  SpindleRig rig(spindle_config());
  rig.run({1000, SpindleDirection::Clockwise}, 1000);
  rig.run({1000, SpindleDirection::Clockwise}, 500, false);
  EXPECT_NEAR(rig.in.speed_rpm, 500, 1e-6);
  EXPECT_FALSE(rig.in.at_speed);
}

}  // namespace
}  // namespace opencnc::machine
