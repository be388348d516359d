// SPDX-License-Identifier: GPL-3.0-or-later
// Machine profiles: the shipped mill loads and runs; bad profiles and overrides are rejected
// with file:line:col and a stable code; overrides are validated like the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/machine/sim_machine.hpp"

namespace opencnc::config {
namespace {

const std::string kMill = std::string(OPENCNC_SOURCE_DIR) + "/configs/mill-3axis.toml";

/// A small valid profile; tests append or replace lines.
const std::string kBase = R"(name = "test"
[axis.x]
max_velocity = 100
max_acceleration = 1000
min_limit = -10
max_limit = 300
)";

std::string all_messages(const Diagnostics& d) {
  std::string s;
  for (const auto& i : d.items()) s += i.format() + "\n";
  return s;
}

/// The first error's code, file, line and column.
struct Where {
  std::string code, file;
  std::uint32_t line = 0, col = 0;
  bool operator==(const Where&) const = default;
};
std::ostream& operator<<(std::ostream& os, const Where& w) {
  return os << w.code << " at " << w.file << ":" << w.line << ":" << w.col;
}
Where first_error(const ProfileLoad& load) {
  for (const auto& d : load.diagnostics.items()) {
    if (d.severity == Severity::Error) return {d.code, d.file, d.line, d.col};
  }
  return {};
}

TEST(MachineProfile, MillLoadsCleanly) {
  const ProfileLoad load = load_profile(kMill);
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_TRUE(load.diagnostics.empty()) << all_messages(load.diagnostics);
  const MachineProfile& p = *load.profile;
  EXPECT_EQ(p.name, "mill-3axis");
  EXPECT_EQ(p.servo_period_s, 0.001);
  EXPECT_EQ(p.sim_substeps, 10);
  EXPECT_EQ(p.axis_mask(), AxisMask::from_letters("XYZ"));
  for (const AxisProfile& a : p.axes) {
    EXPECT_EQ(a.max_velocity, 100.0);
    EXPECT_EQ(a.max_acceleration, 1000.0);
    EXPECT_EQ(a.max_jerk, 0.0);
    EXPECT_EQ(a.joint, index(a.axis));
    EXPECT_EQ(a.homing.method, HomingMethod::Immediate);
  }
  EXPECT_EQ(p.find(Axis::Y)->sim.inertia, 250.0);
  EXPECT_EQ(p.find(Axis::A), nullptr);
  EXPECT_TRUE(p.spindle.present);
  EXPECT_EQ(p.spindle.sim.encoder_counts_per_rev, 4096);
  EXPECT_EQ(p.probe.sim_joint, 2);
  EXPECT_EQ(p.interpreter.dialect, Dialect::LinuxCnc);
  EXPECT_EQ(p.planner.default_tolerance, 0.0);  // G64 without P: no bound, as in LinuxCNC
}

// The profile's machine moves X 100 mm with the profile's limits (trapezoid at 100 mm/s and
// 1000 mm/s²) and keeps its following error far inside max_following_error.
// The flame cutter of the retrace example: its torch sequence and heights (docs/retrace.md).
TEST(MachineProfile, FlameCutterLoadsWithItsTorch) {
  const ProfileLoad load = load_profile(OPENCNC_SOURCE_DIR "/configs/flame-cutter.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_TRUE(load.diagnostics.empty()) << all_messages(load.diagnostics);
  const CuttingProfile& c = load.profile->cutting;
  EXPECT_TRUE(c.present);
  EXPECT_EQ(c.torch_output, 0);
  EXPECT_EQ(c.preheat_output, 1);
  EXPECT_EQ(c.cut_output, 2);
  EXPECT_EQ(c.ignite_s + c.preheat_s + c.pierce_s, 6.5);
  EXPECT_TRUE(c.has_safe_height);
  EXPECT_EQ(c.safe_height_mm, 40.0);
  EXPECT_EQ(c.pierce_lift_mm, 5.0);
  EXPECT_FALSE(load_profile(kMill).profile->cutting.present);
}

TEST(MachineProfile, MillSimulationFollowsATrapezoid) {
  const ProfileLoad load = load_profile(kMill);
  ASSERT_TRUE(load.ok());
  machine::SimMachine m(sim_machine_config(*load.profile));
  EXPECT_EQ(m.capabilities().joint_count, 3);
  machine::MachineOutputs out;
  out.estop_release = true;
  for (int j = 0; j < 3; ++j) out.joints[static_cast<std::size_t>(j)].enable = true;
  const double v = 100, a = 1000, d = 100;  // 0.1 s up, 0.9 s cruise, 0.1 s down
  auto pos = [&](double t) {
    const double ta = v / a, tc = d / v - ta;
    if (t < ta) return 0.5 * a * t * t;
    if (t < ta + tc) return 0.5 * a * ta * ta + v * (t - ta);
    const double td = std::min(t - ta - tc, ta);
    return d - 0.5 * a * (ta - td) * (ta - td);
  };
  double worst = 0;
  machine::MachineInputs in;
  for (int k = 0; k < 1500; ++k) {
    const double t = k * 0.001;
    out.joints[0].position = pos(t);
    out.joints[0].velocity_ff = (pos(t + 0.0005) - pos(t - 0.0005)) / 0.001;
    m.read(in);
    worst = std::max(worst, std::abs(out.joints[0].position - in.joints[0].position));
    m.write(out);
  }
  m.read(in);
  EXPECT_NEAR(in.joints[0].position, 100.0, 1e-3);
  EXPECT_GT(worst, 1e-4);  // there is a following error …
  EXPECT_LT(worst, 0.05);  // … of microns, far below the 0.5 mm limit
}

struct BadCase {
  const char* name;
  std::string text;
  Where expected;
};

class BadProfile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadProfile, IsRejectedAtThePlaceOfTheProblem) {
  const BadCase& c = GetParam();
  const ProfileLoad load = parse_profile(c.text, "bad.toml");
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), c.expected) << all_messages(load.diagnostics);
}

std::string with(const std::string& extra) {
  return kBase + extra;
}
std::string replaced(const std::string& from, const std::string& to) {
  std::string s = kBase;
  s.replace(s.find(from), from.size(), to);
  return s;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadProfile,
    ::testing::Values(
        BadCase{"NegativeAcceleration",
                replaced("max_acceleration = 1000", "max_acceleration = -5"),
                {"config.range", "bad.toml", 4, 20}},
        BadCase{"UnknownKey", with("max_vel = 3\n"), {"config.unknown-key", "bad.toml", 7, 1}},
        BadCase{"DuplicateAxis",
                with("[axis.X]\nmax_velocity = 1\n"),
                {"config.duplicate-axis", "bad.toml", 7, 7}},
        BadCase{"LimitsReversed",
                replaced("min_limit = -10", "min_limit = 400"),
                {"config.limits", "bad.toml", 5, 13}},
        BadCase{"WrongType",
                replaced("max_velocity = 100", "max_velocity = \"fast\""),
                {"config.type", "bad.toml", 3, 16}},
        BadCase{"MissingKey", replaced("max_velocity = 100\n", ""), {"config.missing-key", "bad.toml", 2, 1}},
        BadCase{"Syntax", with("max_jerk = = 3\n"), {"config.syntax", "bad.toml", 7, 12}},
        BadCase{"NotAnAxis", with("[axis.q]\nmax_velocity = 1\n"), {"config.axis-letter", "bad.toml", 7, 7}},
        BadCase{"RotaryKeyOnLinearAxis",
                with("[axis.x.sim]\ninertia_kg_m2 = 1\n"),
                {"config.not-applicable", "bad.toml", 8, 17}},
        BadCase{"StepperKeyOnServo",
                with("steps_per_unit = 200\n"),
                {"config.not-applicable", "bad.toml", 7, 18}},
        BadCase{"HomingWithoutSwitch",
                with("[axis.x.homing]\nmethod = \"switch\"\nsearch_velocity = 10\nlatch_velocity = -1\n"),
                {"config.homing", "bad.toml", 7, 1}},
        BadCase{"HomeOutsideLimits",
                with("[axis.x.homing]\nposition = 500\n"),
                {"config.homing", "bad.toml", 7, 1}},
        BadCase{
            "SubstepDoesNotDivide", with("[sim]\nsubstep_s = 0.0003\n"), {"config.range", "bad.toml", 8, 13}},
        BadCase{"PitchTableNotIncreasing",
                with("[axis.x.sim]\npitch_error = [[0, 0], [10, 0.001], [5, 0]]\n"),
                {"config.range", "bad.toml", 8, 37}},
        BadCase{"ProbeOnMissingAxis",
                with("[probe.sim]\naxis = \"z\"\ntrip = [-inf, -5]\n"),
                {"config.range", "bad.toml", 8, 8}},
        BadCase{"UnstablePositionLoop",
                with("[axis.x.sim]\nposition_gain = 500\n"),
                {"config.range", "bad.toml", 8, 17}},
        BadCase{"NoName", replaced("name = \"test\"\n", ""), {"config.missing-key", "bad.toml", 1, 1}},
        BadCase{"AxisMapNotAnExchange",
                with("[interpreter]\naxis_map = \"X=Z,Y=Z\"\n"),
                {"config.range", "bad.toml", 8, 12}},
        BadCase{"ToolChangeOutsideTheSoftLimits",
                with("[tool_change]\nposition = { X = 500.0 }\n"),
                {"config.range", "bad.toml", 8, 18}},
        BadCase{"ToolChangeOnAnAxisTheMachineLacks",
                with("[tool_change]\nposition = { X = 0.0, Z = 0.0 }\n"),
                {"config.axis-letter", "bad.toml", 8, 27}},
        BadCase{"ToolChangeNotAnAxisLetter",
                with("[tool_change]\nposition = { Q = 0.0 }\n"),
                {"config.unknown-key", "bad.toml", 8, 14}},
        BadCase{"ToolChangeWithoutAPosition",
                with("[tool_change]\nz_first = false\n"),
                {"config.missing-key", "bad.toml", 7, 1}},
        BadCase{"ToolChangeOrderNotABoolean",
                with("[tool_change]\nposition = { X = 0.0 }\nz_first = \"yes\"\n"),
                {"config.type", "bad.toml", 9, 11}},
        BadCase{"UnknownMachineKind",
                with("[interpreter]\nmachine = \"router\"\n"),
                {"config.range", "bad.toml", 8, 11}},
        BadCase{"FrictionOrder",
                with("[axis.x.sim]\ncoulomb_friction_n = 50\nstatic_friction_n = 40\n"),
                {"config.range", "bad.toml", 9, 21}},
        BadCase{"FrictionCompensationAboveStaticFriction",
                with("[axis.x.sim]\ncoulomb_friction_n = 40\nstatic_friction_n = 50\nfriction_compensation_n "
                     "= 60\n"),
                {"config.range", "bad.toml", 10, 27}},
        BadCase{"FrictionCompensationWithoutVelocityIntegrator",
                with("[axis.x.sim]\nfriction_compensation_n = 10\nvelocity_integral_hz = 0\n"),
                {"config.range", "bad.toml", 9, 24}},
        BadCase{"AccelerationFeedForwardTooLarge",
                with("[axis.x.sim]\nacceleration_feed_forward = 2\n"),
                {"config.range", "bad.toml", 8, 29}},
        BadCase{"PeakDecelerationBelowMaxAcceleration",
                with("peak_deceleration = 500\n"),
                {"config.limits", "bad.toml", 7, 21}},
        BadCase{"PeakDecelerationZero", with("peak_deceleration = 0\n"), {"config.range", "bad.toml", 7, 21}},
        BadCase{"DcLinkCapacitanceZero",
                with("[power]\ndc_link_capacitance_f = 0\n"),
                {"config.range", "bad.toml", 8, 25}},
        BadCase{"DcLinkIdlePowerWithoutCapacitance",
                with("[power]\ndc_link_idle_power_w = 150\n"),
                {"config.not-applicable", "bad.toml", 8, 24}},
        BadCase{"UpsHoldingTheLinkWithoutAUps",
                with("[power]\n[power.sim]\nups_holds_dc_link = true\n"),
                {"config.not-applicable", "bad.toml", 9, 21}},
        BadCase{"TorchOnAnOutputTheMachineLacks",
                with("[process.cutting]\ntorch_output = 7\n"),
                {"config.range", "bad.toml", 8, 16}},
        BadCase{"NegativePreheatTime",
                with("[process.cutting]\ntorch_output = 0\npreheat_s = -1\n"),
                {"config.range", "bad.toml", 9, 13}}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(MachineProfile, UnknownKeyMessageListsTheAllowedKeys) {
  const ProfileLoad load = parse_profile(with("max_vel = 3\n"), "bad.toml");
  ASSERT_FALSE(load.diagnostics.items().empty());
  const std::string msg = load.diagnostics.items()[0].format();
  EXPECT_NE(msg.find("bad.toml:7:1: error: unknown key 'max_vel' in [axis.x]"), std::string::npos) << msg;
  EXPECT_NE(msg.find("max_velocity"), std::string::npos) << msg;
}

TEST(MachineProfile, ReportsEveryProblemInOnePass) {
  std::string text = replaced("max_acceleration = 1000", "max_acceleration = -5");
  text += "colour = 3\n[spindle]\nmax_rpm = -1\n";
  const ProfileLoad load = parse_profile(text, "bad.toml");
  EXPECT_EQ(load.diagnostics.error_count(), 3u) << all_messages(load.diagnostics);
}

TEST(MachineProfile, NoisySwitchesAreAWarningOnly) {
  const ProfileLoad load = parse_profile(
      with("[axis.x.switches]\nhome = [290, inf]\nhysteresis = 0.01\nnoise = 0.01\n"), "w.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  ASSERT_EQ(load.diagnostics.warning_count(), 1u);
  EXPECT_EQ(load.diagnostics.items()[0].code, "config.switch-chatter");
  EXPECT_TRUE(load.profile->find(Axis::X)->switches.home.present);
  EXPECT_EQ(load.profile->find(Axis::X)->switches.home.from, 290.0);
}

TEST(MachineProfile, RotaryAndStepperAxes) {
  const ProfileLoad load = parse_profile(with(R"([axis.c]
max_velocity = 3600
max_acceleration = 36000
wrapped = true
[axis.c.sim]
inertia_kg_m2 = 0.2
peak_torque_nm = 100
[axis.y]
drive = "stepper"
steps_per_unit = 400
max_velocity = 50
max_acceleration = 500
min_limit = 0
max_limit = 200
[axis.y.sim]
backlash = 0.05
pitch_error = [[0, 0], [100, 0.01], [200, 0.015]]
)"),
                                         "r.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const MachineProfile& p = *load.profile;
  ASSERT_EQ(p.axes.size(), 3u);
  EXPECT_EQ(p.axes[1].axis, Axis::Y);  // joints in axis order, not file order
  EXPECT_EQ(p.axes[2].axis, Axis::C);
  EXPECT_EQ(p.axes[2].joint, 2);
  EXPECT_TRUE(p.axes[2].rotary);
  EXPECT_TRUE(p.axes[2].wrapped);
  EXPECT_EQ(p.axes[2].sim.inertia, 0.2);
  EXPECT_EQ(p.axes[1].drive, machine::JointDrive::Stepper);
  EXPECT_EQ(p.axes[1].counts_per_unit, 400);
  EXPECT_EQ(p.axes[1].sim.pitch_error.size(), 3u);
  const machine::SimMachineConfig sim = sim_machine_config(p);
  EXPECT_EQ(sim.joint_count, 3);
  EXPECT_EQ(sim.joints[1].drive, machine::JointDrive::Stepper);
  EXPECT_TRUE(sim.joints[2].rotary);
}

// From TOML to the simulated machine's inputs: a stepper axis with a deceleration dog and a
// home switch for decel_home homing; its switches change where the profile puts them.
TEST(MachineProfile, SwitchesFromTheProfileDriveTheSimulatedInputs) {
  const ProfileLoad load = parse_profile(R"(name = "drill"
[axis.x]
drive = "stepper"
steps_per_unit = 1000
max_velocity = 50
max_acceleration = 500
min_limit = 0
max_limit = 300
[axis.x.homing]
method = "decel_home"
position = 300
search_velocity = 20
latch_velocity = 1
[axis.x.switches]
decel = [290, 303]
home = [301, 302]
limit_max = 305
hysteresis = 0.01
noise = 0
[axis.x.sim]
start_position = 280
)",
                                         "drill.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const AxisProfile& x = *load.profile->find(Axis::X);
  EXPECT_EQ(x.homing.method, HomingMethod::DecelHome);
  EXPECT_EQ(x.homing.search_velocity, 20);
  machine::SimMachine m(sim_machine_config(*load.profile));
  EXPECT_EQ(m.capabilities().joints[0].switches,
            machine::kSwitchDecel | machine::kSwitchHome | machine::kSwitchLimitPos);
  machine::MachineOutputs out;
  out.estop_release = true;
  out.joints[0].enable = true;
  machine::MachineInputs in;
  double decel_at = -1, home_at = -1, limit_at = -1;
  for (std::int64_t steps = 280000; steps <= 306000; steps += 10) {  // 10 µm per period
    out.joints[0].step_position = steps;
    m.write(out);
    m.read(in);
    if (in.joints[0].decel && decel_at < 0) decel_at = in.joints[0].position;
    if (in.joints[0].home && home_at < 0) home_at = in.joints[0].position;
    if (in.joints[0].limit_pos && limit_at < 0) limit_at = in.joints[0].position;
  }
  EXPECT_DOUBLE_EQ(decel_at, 290.0);
  EXPECT_DOUBLE_EQ(home_at, 301.0);
  EXPECT_DOUBLE_EQ(limit_at, 305.0);
  EXPECT_FALSE(in.joints[0].decel);  // passed the end of the dog
}

// --- overrides -------------------------------------------------------------------------

ProfileLoad with_overrides(std::vector<std::string> sets) {
  return load_profile(kMill, sets);
}

TEST(MachineProfile, ToolChangePositionIsReadWithItsPlace) {
  const ProfileLoad none = parse_profile(kBase, "p.toml");
  ASSERT_TRUE(none.ok()) << all_messages(none.diagnostics);
  EXPECT_EQ(none.profile->tool_change.axes.count(), 0);  // no key: M6 does not move
  const ProfileLoad load =
      parse_profile(with("[tool_change]\nposition = { x = -10 }\nz_first = false\n"), "p.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const ToolChangeProfile& tc = load.profile->tool_change;
  EXPECT_EQ(tc.axes, AxisMask::from_letters("X"));
  EXPECT_EQ(tc.position[Axis::X], -10.0);  // on the soft limit is inside
  EXPECT_FALSE(tc.z_first);
  EXPECT_EQ(tc.where, "p.toml:8:12");
  // From an override too, where it is checked like the file.
  const ProfileLoad set = with_overrides({"tool_change.position.Z=2001"});
  EXPECT_EQ(first_error(set), (Where{"config.range", "--set", 1, 24})) << all_messages(set.diagnostics);
}

TEST(ProfileOverride, ReplacesValues) {
  const ProfileLoad load = with_overrides({"axis.x.max_velocity=200", "interpreter.dialect=fanuc",
                                           "axis.Y.sim.mass_kg = 300", "spindle.sim.acceleration_rpm_s=1e3"});
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_EQ(load.profile->find(Axis::X)->max_velocity, 200.0);
  EXPECT_EQ(load.profile->find(Axis::Y)->max_velocity, 100.0);
  EXPECT_EQ(load.profile->find(Axis::Y)->sim.inertia, 300.0);
  EXPECT_EQ(load.profile->interpreter.dialect, Dialect::Fanuc);
  EXPECT_EQ(load.profile->spindle.sim.acceleration_rpm_s, 1000.0);
}

TEST(ProfileOverride, FanucLatheWithAnAxisExchange) {
  const ProfileLoad load = with_overrides({"interpreter.dialect=fanuc", "interpreter.machine=lathe",
                                           "interpreter.axis_map=\"X=Y\""});
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const InterpreterOptions& o = load.profile->interpreter;
  EXPECT_EQ(o.machine, MachineKind::Lathe);
  EXPECT_EQ(o.axis_map[index(Axis::X)], Axis::Y);
  EXPECT_EQ(o.axis_map[index(Axis::Y)], Axis::X);
}

TEST(ProfileOverride, AddsKeys) {
  const ProfileLoad load = with_overrides({"axis.z.max_jerk=50000", "axis.x.sim.backlash=0.004"});
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_EQ(load.profile->find(Axis::Z)->max_jerk, 50000.0);
  EXPECT_EQ(load.profile->find(Axis::X)->sim.backlash, 0.004);
}

TEST(ProfileOverride, IsValidatedWhereItWasWritten) {
  const ProfileLoad load = with_overrides({"axis.y.max_velocity=150", "axis.x.max_acceleration=-5"});
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), (Where{"config.range", "--set", 2, 25})) << all_messages(load.diagnostics);
}

TEST(ProfileOverride, UnknownKeyIsReportedAtTheOverride) {
  const ProfileLoad load = with_overrides({"axis.x.max_velocty=150"});
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), (Where{"config.unknown-key", "--set", 1, 8}))
      << all_messages(load.diagnostics);
}

TEST(ProfileOverride, MalformedOverridesAreRejected) {
  for (const char* bad : {"axis.x.max_velocity", "=3", "axis..x=3", "axis.x.max_velocity=[1,"}) {
    const ProfileLoad load = with_overrides({bad});
    EXPECT_FALSE(load.ok()) << bad;
    EXPECT_EQ(first_error(load).code, "config.override") << bad << "\n" << all_messages(load.diagnostics);
    EXPECT_EQ(first_error(load).file, "--set") << bad;
  }
}

TEST(ProfileOverride, BareWordThatShouldBeANumberIsATypeError) {
  const ProfileLoad load = with_overrides({"axis.x.max_velocity=fast"});
  EXPECT_EQ(first_error(load).code, "config.type") << all_messages(load.diagnostics);
}

// --- files -----------------------------------------------------------------------------

TEST(ProfileFile, MissingFileIsAnError) {
  const ProfileLoad load = load_profile("/nonexistent/profile.toml");
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), (Where{"config.file", "/nonexistent/profile.toml", 0, 0}));
}

TEST(ProfileFile, RelativePathsAreResolvedAgainstTheProfileFolder) {
  const auto dir = std::filesystem::temp_directory_path() / "opencnc_profile_test";
  std::filesystem::create_directories(dir / "subs");
  {
    std::ofstream f(dir / "m.toml");
    f << kBase << "[interpreter]\nsubroutine_path = [\"subs\", \"missing\"]\ntool_table = \"tools.tbl\"\n";
  }
  std::ofstream(dir / "tools.tbl") << "T1 P1 Z10 D6\n";  // the table must be there to be named
  const ProfileLoad load = load_profile(dir / "m.toml");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const InterpreterOptions& o = load.profile->interpreter;
  ASSERT_EQ(o.subroutine_path.size(), 2u);
  EXPECT_EQ(o.subroutine_path[0], (dir / "subs").string());
  EXPECT_EQ(o.tool_table, (dir / "tools.tbl").string());
  ASSERT_EQ(load.diagnostics.warning_count(), 1u);  // "missing" is not a folder
  EXPECT_EQ(load.diagnostics.items()[0].code, "config.path");
  std::filesystem::remove_all(dir);
}

// --- property: random overrides never crash and every error has a place ------------------

TEST(ProfileOverride, RandomOverridesAreAlwaysAnsweredPrecisely) {
  const std::vector<std::string> keys = {"servo_period_s",
                                         "axis.x.max_velocity",
                                         "axis.x.min_limit",
                                         "axis.y.max_limit",
                                         "axis.z.max_acceleration",
                                         "axis.x.sim.mass_kg",
                                         "axis.y.sim.position_gain",
                                         "axis.z.sim.velocity_bandwidth_hz",
                                         "axis.x.switches.noise",
                                         "axis.x.homing.method",
                                         "sim.substep_s",
                                         "spindle.max_rpm",
                                         "io.digital_inputs",
                                         "planner.lookahead",
                                         "probe.sim.trip",
                                         "axis.x.drive",
                                         "axis.y.sim.pitch_error",
                                         "axis.x",
                                         "name",
                                         "axis.w.max_velocity"};
  const std::vector<std::string> values = {"0",        "-1",   "1e300", "0.5",    "3",
                                           "\"text\"", "word", "true",  "[1, 2]", "[[0, 0], [1, 1]]",
                                           "inf",      "nan",  "1000",  "{}",     "\"stepper\""};
  machine::SplitMix64 rng(2024);
  int ok = 0;
  for (int n = 0; n < 400; ++n) {
    std::vector<std::string> sets;
    const int count = 1 + static_cast<int>(rng.next() % 3);
    for (int i = 0; i < count; ++i) {
      sets.push_back(keys[rng.next() % keys.size()] + "=" + values[rng.next() % values.size()]);
    }
    const ProfileLoad load = with_overrides(sets);
    if (load.ok()) {
      ++ok;
      for (const AxisProfile& a : load.profile->axes) {
        ASSERT_GT(a.max_velocity, 0);
        ASSERT_TRUE(a.wrapped || a.min_limit < a.max_limit);
      }
      continue;
    }
    for (const Diagnostic& d : load.diagnostics.items()) {
      ASSERT_EQ(d.code.rfind("config.", 0), 0u) << d.format();
      ASSERT_FALSE(d.file.empty()) << d.format();
      ASSERT_GT(d.line, 0u) << d.format();
    }
  }
  EXPECT_GT(ok, 10);  // the generator does produce valid overrides too
}

}  // namespace
}  // namespace opencnc::config
