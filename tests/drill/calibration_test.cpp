// SPDX-License-Identifier: GPL-3.0-or-later
// Calibration on the drill: the midpoint's home reference against a single edge's, the
// positioning test before and after the measured compensation, the table written into a profile's
// text with everything else kept.
#include <gtest/gtest.h>

#include <string>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/config/profile_writer.hpp"
#include "opencnc/drill/calibration.hpp"

namespace opencnc::controller {
namespace {

config::MachineProfile drill() {
  const config::ProfileLoad load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.toml");
  EXPECT_TRUE(load.ok());
  return *load.profile;
}

// The issue's target: the midpoint's spread at most 1 µm, and smaller than a single edge's (which
// drifts 2 µm/K with the 10 K the runs span).
TEST(Calibration, MidpointSpreadIsBelowAMicrometreAndBelowTheSingleEdge) {
  drill::HomingSpreadOptions o;
  o.runs = 8;
  o.seed = 3;
  const drill::HomingSpread h = drill::homing_spread(drill(), o);
  EXPECT_EQ(h.axes, AxisMask::from_letters("XY"));
  EXPECT_EQ(h.runs, 8);
  for (Axis a : {Axis::X, Axis::Y}) {
    const auto i = static_cast<std::size_t>(index(a));
    EXPECT_LE(h.midpoint_spread[i], 0.001) << letter(a);
    EXPECT_GT(h.single_edge_spread[i], 0.005) << letter(a);
    EXPECT_LT(h.midpoint_spread[i], h.single_edge_spread[i]) << letter(a);
  }
  EXPECT_GE(h.temperature_min_c, 15.0);
  EXPECT_LE(h.temperature_max_c, 25.0);
}

// Y's screw (0 … −12 µm) and backlash (15 µm) uncompensated, then with the tables measured: what
// is left is the steppers' 1.5625 µm step.
TEST(Calibration, PositioningBeforeAndAfterTheMeasuredTable) {
  const config::MachineProfile p = drill();
  drill::PositioningOptions o;
  o.axes = AxisMask::from_letters("Y");
  const drill::Positioning before = drill::measure_positioning(drill::without_compensation(p), o);
  const drill::AxisPositioning& b = before.axis[index(Axis::Y)];
  ASSERT_EQ(b.targets.size(), 9u);  // 0 … 400 every 50 within −5 … 405
  EXPECT_EQ(b.targets.front(), 0.0);
  EXPECT_EQ(b.targets.back(), 400.0);
  EXPECT_EQ(b.mean_up.front(), 0.0);  // the scale is zeroed there
  EXPECT_NEAR(b.reversal, 0.015, 0.0005);
  EXPECT_NEAR(b.mean_up.back(), -0.012, 0.0005);
  EXPECT_NEAR(b.accuracy, 0.027, 0.001);
  config::MachineProfile compensated = p;
  for (config::AxisProfile& ax : compensated.axes) {
    if (ax.axis == Axis::Y) ax.compensation = drill::compensation_from(b, ax);
  }
  const config::CompensationProfile& y = compensated.find(Axis::Y)->compensation;
  EXPECT_EQ(y.backlash, 0.0);
  EXPECT_EQ(y.forward, b.mean_up);
  EXPECT_EQ(y.takeup_velocity, 2.0);  // the profile's take-up limits stay
  const drill::Positioning after = drill::measure_positioning(compensated, o);
  const drill::AxisPositioning& a = after.axis[index(Axis::Y)];
  EXPECT_LE(a.accuracy, 0.002);
  EXPECT_LE(a.repeatability, 0.002);
  EXPECT_LE(a.reversal, 0.0016);
}

const char* kProfileText = R"(name = "t"   # a comment that stays
[axis.x]
max_velocity = 50
max_acceleration = 300
min_limit = 0
max_limit = 100

[axis.x.compensation]
# the old table
backlash = 0.02

# Y: comments that lead into the next table stay with it
[axis.y]
max_velocity = 50
max_acceleration = 300
min_limit = 0
max_limit = 100
)";

config::CompensationProfile table() {
  config::CompensationProfile c;
  c.present = true;
  c.positions = {0, 50, 100};
  c.forward = {0, 0.0031, -0.0004};
  c.reverse = {0.015, 0.0182, 0.0148};
  c.takeup_velocity = 5;
  c.takeup_acceleration = 30;
  return c;
}

TEST(ProfileWriter, ReplacesTheTableAndKeepsEverythingElse) {
  std::string error;
  const auto text = config::with_compensation(kProfileText, Axis::X, table(), error);
  ASSERT_TRUE(text) << error;
  EXPECT_EQ(text->find("the old table"), std::string::npos);
  EXPECT_NE(text->find("# a comment that stays"), std::string::npos);
  EXPECT_NE(text->find("# Y: comments that lead into the next table stay with it\n[axis.y]"),
            std::string::npos);
  const config::ProfileLoad load = config::parse_profile(*text, "t.toml");
  ASSERT_TRUE(load.ok()) << *text;
  const config::CompensationProfile& c = load.profile->find(Axis::X)->compensation;
  EXPECT_EQ(c.positions, table().positions);
  EXPECT_EQ(c.forward, table().forward);
  EXPECT_EQ(c.reverse, table().reverse);
  EXPECT_EQ(c.backlash, 0.0);
}

TEST(ProfileWriter, AddsATableAfterTheAxis) {
  std::string error;
  const auto text = config::with_compensation(kProfileText, Axis::Y, table(), error);
  ASSERT_TRUE(text) << error;
  const config::ProfileLoad load = config::parse_profile(*text, "t.toml");
  ASSERT_TRUE(load.ok()) << *text;
  EXPECT_EQ(load.profile->find(Axis::Y)->compensation.forward, table().forward);
  EXPECT_EQ(load.profile->find(Axis::X)->compensation.backlash, 0.02);  // X's untouched
}

TEST(ProfileWriter, RefusesWhatItCannotEditSafely) {
  std::string error;
  // The compensation written as dotted keys in [axis.x]: a second definition would not read back.
  const std::string dotted =
      "name = \"t\"\n[axis.x]\nmax_velocity = 50\nmax_acceleration = 300\nmin_limit = 0\n"
      "max_limit = 100\ncompensation.backlash = 0.01\n";
  EXPECT_FALSE(config::with_compensation(dotted, Axis::X, table(), error));
  EXPECT_NE(error.find("read back"), std::string::npos) << error;
  EXPECT_FALSE(config::with_compensation(kProfileText, Axis::Z, table(), error));
  EXPECT_NE(error.find("no [axis.z]"), std::string::npos) << error;
}

}  // namespace
}  // namespace opencnc::controller
