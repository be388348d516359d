// SPDX-License-Identifier: GPL-3.0-or-later
// [probe.reference_sphere] and [[sim.electrode]]: read into the profile and its simulated
// machine, and bad values rejected at file:line:col.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {
namespace {

/// X Y Z and [probe] (lines 1–17); tests append from line 18.
const std::string kBase = R"(name = "t"
[axis.x]
max_velocity = 50
max_acceleration = 300
min_limit = -300
max_limit = 300
[axis.y]
max_velocity = 50
max_acceleration = 300
min_limit = -300
max_limit = 300
[axis.z]
max_velocity = 50
max_acceleration = 300
min_limit = -300
max_limit = 100
[probe]
)";

const std::string kSphere = R"([probe.reference_sphere]
position = [100.0, 50.0, -150.0]
diameter = 10.0
safe_z = -60.0
)";

std::string first_error(const ProfileLoad& load) {
  for (const auto& d : load.diagnostics.items()) {
    if (d.severity == Severity::Error) return d.format() + " [" + d.code + "]";
  }
  return "";
}

TEST(ReferenceSphere, IsReadWithItsDefaultsAndMadeTheSimulatedProbe) {
  const ProfileLoad load =
      parse_profile(kBase + kSphere + "[probe.reference_sphere.sim]\nnoise = 0.0001\n", "p.toml");
  ASSERT_TRUE(load.ok()) << first_error(load);
  const ReferenceSphereProfile& s = load.profile->probe.reference_sphere;
  EXPECT_TRUE(s.present);
  EXPECT_EQ(s.position, (Vec3{100, 50, -150}));
  EXPECT_EQ(s.touches_around, 4);
  EXPECT_EQ(s.clearance, 1.0);
  const machine::SimMachineConfig c = sim_machine_config(*load.profile);
  EXPECT_TRUE(c.probe.sphere.present);
  EXPECT_EQ(c.probe.joint, -1);
  EXPECT_EQ(c.probe.sphere.radius, 5.0);
  EXPECT_EQ(c.probe.sphere.noise, 0.0001);
  EXPECT_EQ(c.probe.sphere.joints, (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(s.fast_feed, 0.0) << "one touch a direction unless fast_feed is given";
  EXPECT_EQ(c.probe.sphere.b_joint, -1) << "no B: the sphere does not turn";
}

TEST(ReferenceSphere, BsAxisIsReadAndItsDirectionMadeAUnitVector) {
  const std::string b =
      "[axis.b]\ntype = \"rotary\"\nmax_velocity = 30\nmax_acceleration = 300\n"
      "min_limit = -95\nmax_limit = 95\n";
  const ProfileLoad load =
      parse_profile(kBase + b + kSphere +
                        "b_axis = [100.0, -170.0]\nb_axis_direction = [0.0, 2.0, 0.002]\n"
                        "[probe.reference_sphere.sim]\nb_axis = [100.01, -170.02]\n"
                        "b_axis_direction = [0.001, 1.0, 0.0]\n",
                    "p.toml");
  ASSERT_TRUE(load.ok()) << first_error(load);
  const ReferenceSphereProfile& s = load.profile->probe.reference_sphere;
  EXPECT_TRUE(s.has_b_axis);
  EXPECT_EQ(s.b_axis, (std::array<double, 2>{100.0, -170.0}));
  EXPECT_NEAR(s.b_axis_direction[1], 1 / std::hypot(1.0, 0.001), 1e-15);
  EXPECT_NEAR(s.b_axis_direction[2], 0.001 / std::hypot(1.0, 0.001), 1e-15);
  const machine::SimMachineConfig c = sim_machine_config(*load.profile);
  EXPECT_EQ(c.probe.sphere.b_axis, (std::array<double, 2>{100.01, -170.02}));
  EXPECT_NEAR(c.probe.sphere.b_direction[0], 0.001 / std::hypot(1.0, 0.001), 1e-15) << "the true axis";
  const ProfileLoad plain = parse_profile(kBase + b + kSphere, "p.toml");
  ASSERT_TRUE(plain.ok()) << first_error(plain);
  EXPECT_FALSE(plain.profile->probe.reference_sphere.has_b_axis);
  EXPECT_EQ(plain.profile->probe.reference_sphere.b_axis_direction, (Vec3{0, 1, 0}));
}

TEST(SimElectrodes, AreReadIntoTheSimulatedMachine) {
  const ProfileLoad load =
      parse_profile(kBase + kSphere +
                        "[sim]\n[[sim.electrode]]\ntool = 3\noffset = [0.1, -0.2, 50.5]\n"
                        "tip_radius = 0.8\n[[sim.electrode]]\ntool = 4\noffset = [0, 0, 40]\n",
                    "p.toml");
  ASSERT_TRUE(load.ok()) << first_error(load);
  const machine::SimMachineConfig c = sim_machine_config(*load.profile);
  ASSERT_EQ(c.electrode_count, 2);
  EXPECT_EQ(c.electrodes[0].tool, 3);
  EXPECT_EQ(c.electrodes[0].offset, (Vec3{0.1, -0.2, 50.5}));
  EXPECT_EQ(c.electrodes[0].tip_radius, 0.8);
  EXPECT_EQ(c.electrodes[1].tool, 4);
  EXPECT_EQ(c.electrodes[1].tip_radius, 0.0) << "a point tip unless said";
}

struct Bad {
  const char* name;
  std::string extra;
  std::string error;  ///< the start of the first error
};

class BadReferenceSphere : public ::testing::TestWithParam<Bad> {};

TEST_P(BadReferenceSphere, IsRejectedAtItsPlace) {
  const ProfileLoad load = parse_profile(kBase + GetParam().extra, "p.toml");
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load).rfind(GetParam().error, 0), 0u) << first_error(load);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadReferenceSphere,
    ::testing::Values(
        Bad{"PositionNotThreeNumbers",
            "[probe.reference_sphere]\nposition = [1.0, 2.0]\ndiameter = 10\nsafe_z = 0\n",
            "p.toml:19:12: error: probe.reference_sphere.position must be [x, y, z]"},
        Bad{"NoDiameter", "[probe.reference_sphere]\nposition = [0, 0, 0]\nsafe_z = 50\n",
            "p.toml:18:1: error:"},
        Bad{"NegativeDiameter",
            "[probe.reference_sphere]\nposition = [0, 0, 0]\ndiameter = -3\nsafe_z = 50\n",
            "p.toml:20:12: error:"},
        Bad{"SafeZBelowTheTop",
            "[probe.reference_sphere]\nposition = [0, 0, 0]\ndiameter = 10\nsafe_z = 5.5\n",
            "p.toml:21:10: error: probe.reference_sphere.safe_z (5.5) is below the sphere's top"},
        Bad{"TooFewTouches", kSphere + "touches_around = 3\n", "p.toml:22:18: error:"},
        Bad{"BWithoutAxisB", kSphere + "b = 30\n", "p.toml:22:5: error:"},
        Bad{"BackOffNotBelowTheClearance", kSphere + "fast_feed = 600\nback_off = 1.5\n",
            "p.toml:23:12: error: probe.reference_sphere.back_off (1.5) must be below the clearance"},
        Bad{"SimBAxisNotTwoNumbers", kSphere + "[probe.reference_sphere.sim]\nb_axis = [1, 2, 3]\n",
            "p.toml:23:10: error: probe.reference_sphere.sim.b_axis must be [x, z]"},
        Bad{"SimBAxisWithoutAxisB", kSphere + "[probe.reference_sphere.sim]\nb_axis = [1, 2]\n",
            "p.toml:22:1: error: probe.reference_sphere.sim.b_axis: the profile has no B axis"},
        Bad{"BAxisWithoutAxisB", kSphere + "b_axis = [1.0, 2.0]\n",
            "p.toml:22:10: error: probe.reference_sphere.b_axis the profile has no B axis"},
        Bad{"BAxisNotTwoNumbers", kSphere + "b_axis = [1.0]\n",
            "p.toml:22:10: error: probe.reference_sphere.b_axis must be [x, z]"},
        Bad{"BAxisDirectionFarFromY", kSphere + "b_axis_direction = [1.0, 1.0, 0.0]\n",
            "p.toml:22:20: error: probe.reference_sphere.b_axis_direction must point along +Y within 10°"},
        Bad{"SimBAxisDirectionWithoutLength",
            kSphere + "[probe.reference_sphere.sim]\nb_axis_direction = [0.0, 0.0, 0.0]\n",
            "p.toml:23:20: error: probe.reference_sphere.sim.b_axis_direction must point along +Y within 10° "
            "(B turns "
            "about Y): it has no length"},
        Bad{"SimElectrodeNotATable", "[sim]\nelectrode = 3\n",
            "p.toml:19:13: error: sim.electrode must be an array of tables"},
        Bad{"SimElectrodeWithoutTool", "[sim]\n[[sim.electrode]]\noffset = [0, 0, 1]\n",
            "p.toml:19:1: error:"},
        Bad{"SimElectrodeTwice",
            "[sim]\n[[sim.electrode]]\ntool = 2\noffset = [0, 0, 1]\n[[sim.electrode]]\ntool = 2\noffset = "
            "[0, 0, "
            "2]\n",
            "p.toml:23:8: error: sim.electrode[2].tool: tool 2 has a simulated electrode already"},
        Bad{"SimElectrodeOffsetNotThreeNumbers", "[sim]\n[[sim.electrode]]\ntool = 2\noffset = [0, 1]\n",
            "p.toml:21:10: error: sim.electrode[1].offset must be [x, y, z]"},
        Bad{"SimElectrodeNegativeTip",
            "[sim]\n[[sim.electrode]]\ntool = 2\noffset = [0, 0, 1]\ntip_radius = -1\n",
            "p.toml:22:14: error:"},
        Bad{"BothSimulations",
            kSphere + "[probe.reference_sphere.sim]\n[probe.sim]\naxis = \"z\"\ntrip = [-inf, 0]\n",
            "p.toml:23:1: error: [probe.sim] and [probe.reference_sphere.sim] exclude each other"}),
    [](const auto& p) { return std::string(p.param.name); });

}  // namespace
}  // namespace opencnc::config
