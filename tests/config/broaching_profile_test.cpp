// SPDX-License-Identifier: GPL-3.0-or-later
// [process.broaching]: the broach's load levels, retract and log rate and the simulated bore —
// loaded from broach-zc, and rejected at file:line:col when wrong.
#include <gtest/gtest.h>

#include <string>

#include "../support/profile_errors.hpp"
#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {
namespace {

using test::all_messages;
using test::first_error;
using test::Where;

/// X radial, Z master, C slave (lines 1–18); tests append [process.broaching] from line 19.
const std::string kBase = R"(name = "t"
[axis.x]
max_velocity = 5
max_acceleration = 100
min_limit = -1
max_limit = 3
[axis.z]
max_velocity = 150
max_acceleration = 1500
min_limit = -200
max_limit = 1500
[axis.c]
wrapped = true
max_velocity = 360
max_acceleration = 3600
[coupling]
master = "Z"
slave = "C"
)";

TEST(BroachingProfile, TheBroachLoadsItsLevelsAndBore) {
  const ProfileLoad load = load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const BroachingProfile& b = load.profile->broaching;
  EXPECT_TRUE(b.present);
  EXPECT_EQ(b.load_input, 0);
  EXPECT_EQ(b.hold_kn, 4.0);
  EXPECT_EQ(b.retract_kn, 6.0);
  EXPECT_EQ(b.radial, Axis::X);
  EXPECT_EQ(b.retract_lift, -0.5);
  EXPECT_EQ(b.log_rate_hz, 100.0);
  ASSERT_TRUE(b.sim.present);
  EXPECT_EQ(b.sim.bore_end, 600.0);
  EXPECT_EQ(b.sim.radius_mm, 40.0);  // the coupling's radius: the cutter's width in degrees
  const machine::SimMachineConfig sim = sim_machine_config(*load.profile);
  EXPECT_TRUE(sim.broach.present);
  EXPECT_EQ(sim.broach.stroke_joint, 1);
  EXPECT_EQ(sim.broach.rotary_joint, 2);
  EXPECT_EQ(sim.broach.radial_joint, 0);
  // The link the power-fail stop counts on, stated in [power] (the simulated link is the same),
  // and how hard the drives may brake the axes when it would not last.
  EXPECT_EQ(load.profile->power.dc_link_capacitance_f, 0.0047);
  EXPECT_EQ(load.profile->power.dc_link_idle_power_w, 150.0);
  EXPECT_EQ(sim.power.dc_link_capacitance_f, 0.0047);
  EXPECT_EQ(sim.power.idle_power_w, 150.0);
  EXPECT_TRUE(sim.power.ups);
  EXPECT_FALSE(sim.power.ups_holds_dc_link);  // the UPS feeds the control; the link drains
  EXPECT_EQ(load.profile->find(Axis::Z)->peak_deceleration, 6000.0);
  EXPECT_EQ(load.profile->find(Axis::C)->peak_deceleration, 14400.0);
}

struct BadCase {
  const char* name;
  std::string extra;
  Where where;
};

class BadBroachingProfile : public ::testing::TestWithParam<BadCase> {};

// The resume after a power failure as the HMI's recovery dialog offers it: the profile's values.
TEST(BroachingProfile, TheResumesTolerancesAndRunInComeFromPower) {
  const ProfileLoad load =
      parse_profile(kBase + "[power]\nresume_tolerance_mm = 0.02\nresume_run_in_mm = 0\n", "p.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_EQ(load.profile->power.resume_tolerance_mm, 0.02);
  EXPECT_EQ(load.profile->power.resume_tolerance_deg, 0.01);
  EXPECT_EQ(load.profile->power.resume_run_in_mm, 0.0);
  EXPECT_EQ(load.profile->power.resume_run_in_speed_mm_min, 600.0);
}

TEST_P(BadBroachingProfile, IsRejectedAtThePlaceOfTheProblem) {
  const ProfileLoad load = parse_profile(kBase + GetParam().extra, "p.toml");
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), GetParam().where) << all_messages(load.diagnostics);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadBroachingProfile,
    ::testing::Values(
        BadCase{"NoLoadInput", "[process.broaching]\nhold_kn = 4\n", {"config.missing-key", 19, 1}},
        BadCase{"InputBeyondTheMachines",
                "[io]\nanalog_inputs = 2\n[process.broaching]\nload_input = 3\nhold_kn = 4\n",
                {"config.range", 22, 14}},
        BadCase{"NoLevel", "[process.broaching]\nload_input = 0\n", {"config.missing-key", 19, 1}},
        BadCase{
            "NegativeLevel", "[process.broaching]\nload_input = 0\nhold_kn = -4\n", {"config.range", 21, 11}},
        BadCase{"RetractBelowHold",
                "[process.broaching]\nload_input = 0\nhold_kn = 4\nretract_kn = 3\n",
                {"config.limits", 22, 14}},
        BadCase{"RadialIsTheMaster",
                "[process.broaching]\nload_input = 0\nhold_kn = 4\nradial_axis = \"Z\"\n",
                {"config.range", 22, 15}},
        BadCase{"NoLift",
                "[process.broaching]\nload_input = 0\nhold_kn = 4\nretract_lift = 0\n",
                {"config.range", 22, 16}},
        BadCase{"LogFasterThanTheServo",
                "[process.broaching]\nload_input = 0\nhold_kn = 4\nlog_rate_hz = 5000\n",
                {"config.range", 22, 15}},
        BadCase{"ResumeToleranceZero", "[power]\nresume_tolerance_mm = 0\n", {"config.range", 20, 23}},
        BadCase{"UnknownKey",
                "[process.broaching]\nload_input = 0\nhold_kn = 4\nhold = 5\n",
                {"config.unknown-key", 22, 1}},
        BadCase{
            "BoreBackwards",
            "[process.broaching]\nload_input = 0\nhold_kn = 4\n[process.broaching.sim]\nbore_start = 600\n"
            "bore_end = 0\n",
            {"config.limits", 24, 12}},
        BadCase{"DullFactorZero",
                "[process.broaching]\nload_input = 0\nhold_kn = 4\n[process.broaching.sim]\nbore_start = 0\n"
                "bore_end = 600\ndull_factor = 0\n",
                {"config.range", 25, 15}}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace opencnc::config
