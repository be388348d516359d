// SPDX-License-Identifier: GPL-3.0-or-later
// [kinematics]: the five-axis structure and its rotary axes — loaded from mill-5axis-trunnion and
// from text, and rejected at file:line:col when wrong.
#include <gtest/gtest.h>

#include <string>

#include "../support/profile_errors.hpp"
#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {
namespace {

using test::all_messages;
using test::first_error;
using test::Where;

/// X Y Z, a tilting A and an endless C (lines 1–27); tests append from line 28.
const std::string kBase = R"(name = "t"
[axis.x]
max_velocity = 100
max_acceleration = 1000
min_limit = -500
max_limit = 500
[axis.y]
max_velocity = 100
max_acceleration = 1000
min_limit = -500
max_limit = 500
[axis.z]
max_velocity = 100
max_acceleration = 1000
min_limit = -500
max_limit = 500
[axis.a]
type = "rotary"
max_velocity = 180
max_acceleration = 1800
min_limit = -110
max_limit = 110
[axis.c]
type = "rotary"
wrapped = true
max_velocity = 360
max_acceleration = 3600
)";

/// A trunnion in lines 28–37; the C direction is not a unit vector (it is made one).
const std::string kTrunnion = R"([kinematics]
structure = "table-table"
[[kinematics.rotary]]
axis = "A"
direction = [1, 0, 0]
pivot_mm = [0, 0, -250]
[[kinematics.rotary]]
axis = "c"
direction = [0, 0, 2]
pivot_mm = [1.5, 0, -250]
)";

TEST(KinematicsProfile, WithoutTheSectionTheMachineIsIdentity) {
  const ProfileLoad load = parse_profile(kBase, "p.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_EQ(load.profile->kinematics.structure, kinematics::Structure::Identity);
}

TEST(KinematicsProfile, ATrunnionIsReadWithItsAxesInOrder) {
  const ProfileLoad load = parse_profile(kBase + kTrunnion, "p.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const kinematics::Config& k = load.profile->kinematics;
  EXPECT_EQ(k.structure, kinematics::Structure::TableTable);
  EXPECT_EQ(k.rotary[0].joint, Axis::A);
  EXPECT_EQ(k.rotary[1].joint, Axis::C);
  EXPECT_EQ(k.rotary[0].direction, (Vec3{1, 0, 0}));
  EXPECT_EQ(k.rotary[1].direction, (Vec3{0, 0, 1}));
  EXPECT_EQ(k.rotary[1].pivot_mm, (Vec3{1.5, 0, -250}));
}

TEST(KinematicsProfile, TheShippedTrunnionMillLoads) {
  const ProfileLoad load = load_profile(OPENCNC_SOURCE_DIR "/configs/mill-5axis-trunnion.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const kinematics::Config& k = load.profile->kinematics;
  EXPECT_EQ(k.structure, kinematics::Structure::TableTable);
  EXPECT_EQ(k.rotary[0].joint, Axis::A);
  EXPECT_EQ(k.rotary[1].joint, Axis::C);
  // A 100 mm tool's tip 50 mm above A's pivot, the cradle turned a quarter about X (+Y towards
  // +Z): the work's point under the tip is the one that lay 50 mm along +Y at the pivot's height.
  Pose j{};
  j[2] = -100;
  j[index(Axis::A)] = 90;
  const kinematics::ToolPose t = kinematics::forward(k, j, 100);
  EXPECT_NEAR(t.tip_mm[1], 50, 1e-9);
  EXPECT_NEAR(t.tip_mm[2], -250, 1e-9);
}

// The fork head: with B at 90° a 100 mm tool points along −X, its tip 280 mm from B's axis (the
// bearings 180 mm above the gauge point, the tip 100 mm below it): at X −280, Z 180.
TEST(KinematicsProfile, TheShippedForkHeadLoads) {
  const ProfileLoad load = load_profile(OPENCNC_SOURCE_DIR "/configs/mill-5axis-head.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const kinematics::Config& k = load.profile->kinematics;
  EXPECT_EQ(k.structure, kinematics::Structure::HeadHead);
  EXPECT_EQ(k.rotary[0].joint, Axis::C);
  EXPECT_EQ(k.rotary[1].joint, Axis::B);
  Pose j{};
  j[index(Axis::B)] = 90;
  const kinematics::ToolPose t = kinematics::forward(k, j, 100);
  EXPECT_NEAR(t.tip_mm[0], -280, 1e-9);
  EXPECT_NEAR(t.tip_mm[2], 180, 1e-9);
  EXPECT_NEAR(t.axis[0], 1, 1e-12);
}

// The EDM's B takes its line from the reference sphere's section (the drawing's, or as
// calibrate-b wrote it); a calibration that moves it moves the kinematics.
TEST(KinematicsProfile, TheEdmsBTakesTheAxisTheReferenceSphereKeeps) {
  const ProfileLoad load = load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const kinematics::Config& k = load.profile->kinematics;
  EXPECT_EQ(k.structure, kinematics::Structure::TableTable);
  EXPECT_EQ(k.rotary[0].joint, Axis::B);
  EXPECT_EQ(k.rotary[0].direction, (Vec3{0, 1, 0}));
  EXPECT_EQ(k.rotary[0].pivot_mm, (Vec3{120, 80, -90}));
  EXPECT_EQ(k.rotary[1].joint, Axis::C);

  const std::array<std::string, 2> calibrated{
      "probe.reference_sphere.b_axis=[120.012, -90.015]",
      "probe.reference_sphere.b_axis_direction=[0.0002, 1.0, -0.0001]"};
  const ProfileLoad after = load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml", calibrated);
  ASSERT_TRUE(after.ok()) << all_messages(after.diagnostics);
  const kinematics::RotaryAxis& b = after.profile->kinematics.rotary[0];
  EXPECT_EQ(b.pivot_mm, (Vec3{120.012, 80, -90.015}));
  EXPECT_NEAR(b.direction[0], 0.0002, 1e-10);  // made a unit vector
  EXPECT_NEAR(b.direction[2], -0.0001, 1e-10);
  EXPECT_NEAR(norm(b.direction), 1, 1e-15);
}

struct BadCase {
  const char* name;
  std::string extra;
  Where where;
};

class BadKinematicsProfile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadKinematicsProfile, IsRejectedAtThePlaceOfTheProblem) {
  const ProfileLoad load = parse_profile(kBase + GetParam().extra, "p.toml");
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), GetParam().where) << all_messages(load.diagnostics);
}

std::string trunnion_with(const std::string& from, const std::string& to) {
  std::string s = kTrunnion;
  s.replace(s.find(from), from.size(), to);
  return s;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadKinematicsProfile,
    ::testing::Values(
        BadCase{"NoStructure", "[kinematics]\n", {"config.missing-key", 28, 1}},
        BadCase{"UnknownStructure", trunnion_with("table-table", "trunnion"), {"config.range", 29, 13}},
        BadCase{
            "IdentityWithAxes", trunnion_with("table-table", "identity"), {"config.not-applicable", 30, 1}},
        BadCase{"OneRotaryAxis",
                "[kinematics]\nstructure = \"head-head\"\n[[kinematics.rotary]]\naxis = \"C\"\n",
                {"config.type", 30, 1}},
        BadCase{"NoRotaryAxes", "[kinematics]\nstructure = \"head-table\"\n", {"config.missing-key", 28, 1}},
        BadCase{"ALinearAxis", trunnion_with("axis = \"A\"", "axis = \"Y\""), {"config.range", 31, 8}},
        BadCase{
            "AnAxisTheMachineLacks", trunnion_with("axis = \"A\"", "axis = \"B\""), {"config.range", 31, 8}},
        BadCase{"DirectionOfTwoNumbers", trunnion_with("[1, 0, 0]", "[1, 0]"), {"config.type", 32, 13}},
        BadCase{"DirectionOfNoLength", trunnion_with("[1, 0, 0]", "[0, 0, 0]"), {"config.range", 32, 13}},
        BadCase{"NoPivot", trunnion_with("pivot_mm = [0, 0, -250]\n", ""), {"config.missing-key", 30, 1}},
        BadCase{"ParallelAxes", trunnion_with("[1, 0, 0]", "[0, 0, -1]"), {"config.range", 36, 13}},
        BadCase{"TheSameAxisTwice", trunnion_with("axis = \"c\"", "axis = \"A\""), {"config.range", 35, 8}},
        BadCase{"MeasuredWithoutASphere",
                trunnion_with("axis = \"A\"", "axis = \"A\"\nmeasured = \"probe.reference_sphere\""),
                {"config.range", 32, 12}},
        BadCase{"MeasuredElsewhere",
                trunnion_with("axis = \"A\"", "axis = \"A\"\nmeasured = \"laser\""),
                {"config.range", 32, 12}},
        BadCase{"UnknownKey",
                trunnion_with("axis = \"A\"", "axis = \"A\"\nlength = 3"),
                {"config.unknown-key", 32, 1}}),
    [](const ::testing::TestParamInfo<BadCase>& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace opencnc::config
