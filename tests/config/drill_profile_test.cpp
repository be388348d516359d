// SPDX-License-Identifier: GPL-3.0-or-later
// The drill retrofit's profile sections: compensation tables (equal intervals, per direction,
// LinuxCNC comp files of both types), decel_midpoint homing, manual axes, stepper pull-out,
// interlock rules and the handwheel — loaded, and rejected at file:line:col when wrong.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "opencnc/config/profile_loader.hpp"

namespace opencnc::config {
namespace {

const std::string kDrill = std::string(OPENCNC_SOURCE_DIR) + "/configs/drill-retrofit.toml";

std::string all_messages(const Diagnostics& d) {
  std::string s;
  for (const auto& i : d.items()) s += i.format() + "\n";
  return s;
}

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

/// A stepper X (lines 1–8) and a hand-fed Z (lines 9–13); tests append sections.
const std::string kBase = R"(name = "t"
[axis.x]
max_velocity = 50
max_acceleration = 300
min_limit = -5
max_limit = 605
drive = "stepper"
steps_per_unit = 640
[axis.z]
drive = "manual"
max_velocity = 100
max_acceleration = 1000
min_limit = -160
max_limit = 0
)";

ProfileLoad parse(const std::string& extra) {
  return parse_profile(kBase + extra, "p.toml");
}

TEST(DrillProfile, LoadsCleanly) {
  const ProfileLoad load = load_profile(kDrill);
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  EXPECT_TRUE(load.diagnostics.empty()) << all_messages(load.diagnostics);
  const MachineProfile& p = *load.profile;
  const AxisProfile& x = *p.find(Axis::X);
  EXPECT_EQ(x.drive, machine::JointDrive::Stepper);
  EXPECT_TRUE(x.stall_detector);
  EXPECT_EQ(x.homing.method, HomingMethod::DecelMidpoint);
  EXPECT_EQ(x.homing.return_velocity, 1.0);
  EXPECT_EQ(x.homing.overrun, 12.0);
  EXPECT_TRUE(x.homing.return_after_program);
  EXPECT_TRUE(x.switches.home_sensor.present);
  EXPECT_EQ(x.switches.home_sensor.drift_per_k, 0.002);
  ASSERT_EQ(x.compensation.positions.size(), 13u);
  EXPECT_EQ(x.compensation.positions[3], 150.0);
  EXPECT_EQ(x.compensation.forward[3], 0.010);
  EXPECT_EQ(x.compensation.reverse, x.compensation.forward);
  EXPECT_EQ(x.compensation.backlash, 0.02);
  EXPECT_EQ(x.sim.pullout_effort, 1500.0);
  EXPECT_EQ(x.sim.pitch_error.size(), 13u);
  EXPECT_TRUE(p.find(Axis::Z)->manual());
  EXPECT_EQ(p.interlocks.rules.count, 6);
  ASSERT_EQ(p.interlocks.inputs.size(), 2u);
  EXPECT_EQ(p.interlocks.inputs[0].name, "door_open");  // TOML tables read in key order
  ASSERT_EQ(p.sim_input_switches.size(), 1u);
  EXPECT_EQ(p.sim_input_switches[0].channel, 0);
  EXPECT_EQ(p.sim_input_switches[0].joint, 2);
  EXPECT_TRUE(p.handwheel.present);
  EXPECT_EQ(p.handwheel.steps.size(), 3u);
  const machine::SimMachineConfig sim = sim_machine_config(p);
  EXPECT_TRUE(sim.handwheel);
  EXPECT_EQ(sim.input_switches[0].channel, 0);
  EXPECT_TRUE(sim.joints[0].stall_detector);
}

// The planner keeps free what the compensation may use: the take-up limits, the table's steepest
// slope times the axis' limits, and its sharpest bend (0.08 µm/mm at 350 mm) at full speed.
TEST(DrillProfile, CompensationReserve) {
  const ProfileLoad load = load_profile(kDrill);
  ASSERT_TRUE(load.ok());
  const MotionReserve r = compensation_reserve(*load.profile->find(Axis::X), 0.001);
  EXPECT_NEAR(r.velocity, 2.0 + 0.0001 * 50, 1e-12);
  EXPECT_NEAR(r.acceleration, 40.0 + 0.0001 * 300 + 0.00008 * 50 / 0.001, 1e-9);
  EXPECT_EQ(compensation_reserve(*load.profile->find(Axis::Z), 0.001).velocity, 0.0);
}

TEST(DrillProfile, TablesPerDirection) {
  const ProfileLoad load = parse(
      "[axis.x.compensation]\nstart = -10\ninterval = 100\nforward = [0, 0.01, 0.02]\nreverse = [0.005, "
      "0.02, "
      "0.03]\n");
  ASSERT_TRUE(load.ok()) << all_messages(load.diagnostics);
  const CompensationProfile& c = load.profile->find(Axis::X)->compensation;
  EXPECT_EQ(c.positions, (std::vector<double>{-10, 90, 190}));
  EXPECT_EQ(c.reverse[1], 0.02);
  EXPECT_EQ(c.takeup_velocity, 5.0);  // 10 % of the axis' limits by default
  EXPECT_EQ(c.takeup_acceleration, 30.0);
}

/// A comp file in a folder of its own.
class CompFile {
 public:
  explicit CompFile(const std::string& text) {
    dir_ = std::filesystem::temp_directory_path() /
           ("opencnc-comp-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "x.comp") << text;
  }
  ~CompFile() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path() const { return (dir_ / "x.comp").string(); }
  ProfileLoad load(int type) const {
    return parse_profile(kBase + "[axis.x.compensation]\ncomp_file = \"x.comp\"\ncomp_file_type = " +
                             std::to_string(type) + "\n",
                         (dir_ / "p.toml").string(), {}, dir_);
  }

 private:
  std::filesystem::path dir_;
};

// Type 0: where the axis actually is moving up and moving down; type 1: the trims LinuxCNC adds
// to the command (the negative of the error). Both read into errors.
TEST(DrillProfile, LinuxCncCompFilesOfBothTypes) {
  const CompFile f(
      "# nominal forward reverse\n-10 -10.001  -9.999\n\n  0  -0.003   0.002\n 10   9.999  10.000\n");
  const ProfileLoad t0 = f.load(0);
  ASSERT_TRUE(t0.ok()) << all_messages(t0.diagnostics);
  const CompensationProfile& c0 = t0.profile->find(Axis::X)->compensation;
  EXPECT_EQ(c0.positions, (std::vector<double>{-10, 0, 10}));
  EXPECT_NEAR(c0.forward[0], -0.001, 1e-12);
  EXPECT_NEAR(c0.reverse[1], 0.002, 1e-12);
  const CompFile trims("-10 0.005 -0.005\n0 0.002 -0.003\n10 0.003 -0.004\n");
  const ProfileLoad t1 = trims.load(1);
  ASSERT_TRUE(t1.ok()) << all_messages(t1.diagnostics);
  const CompensationProfile& c1 = t1.profile->find(Axis::X)->compensation;
  EXPECT_NEAR(c1.forward[1], -0.002, 1e-12);  // a trim of +0.002 corrects an error of −0.002
  EXPECT_NEAR(c1.reverse[2], 0.004, 1e-12);
}

TEST(DrillProfile, BadCompFileLinesAreReportedInTheCompFile) {
  const CompFile bad("0 0 0\n  10 10.001\n");
  const ProfileLoad load = bad.load(0);
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), (Where{"config.comp-file", bad.path(), 2, 3}));
  const CompFile descending("0 0 0\n10 10 10\n5 5 5\n");
  EXPECT_EQ(first_error(descending.load(1)), (Where{"config.comp-file", descending.path(), 3, 1}));
}

struct BadCase {
  const char* name;
  std::string extra;
  Where where;
};

class BadDrillProfile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadDrillProfile, IsRejectedAtThePlaceOfTheProblem) {
  const ProfileLoad load = parse(GetParam().extra);
  EXPECT_FALSE(load.ok());
  EXPECT_EQ(first_error(load), GetParam().where) << all_messages(load.diagnostics);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadDrillProfile,
    ::testing::Values(
        // Rules name signals the profile has; the column is that of the word.
        BadCase{"UnknownSignal",
                "[interlocks]\nrules = [\"stop spindle when tool_upp\"]\n",
                {"config.interlock", "p.toml", 16, 29}},
        BadCase{"UnknownAction",
                "[interlocks]\nrules = [\"halt spindle when estop\"]\n",
                {"config.interlock", "p.toml", 16, 11}},
        BadCase{"MissingWhen",
                "[interlocks]\nrules = [\"stop spindle estop\"]\n",
                {"config.interlock", "p.toml", 16, 24}},
        BadCase{"UnclosedParenthesis",
                "[interlocks]\nrules = [\"block motion when (estop or x_homed\"]\n",
                {"config.interlock", "p.toml", 16, 46}},
        BadCase{"UnknownOutput",
                "[interlocks]\nrules = [\"set lamp when machine_on\"]\n",
                {"config.interlock", "p.toml", 16, 15}},
        BadCase{
            "SecondRuleOnItsOwnLine",
            "[interlocks.inputs]\ntool_up = 0\n[interlocks]\nrules = [\n  \"stop spindle when tool_up\",\n  "
            "\"block spindle unless z_homed and tool_dwn\",\n]\n",
            {"config.interlock", "p.toml", 20, 37}},
        BadCase{
            "InputChannelMissing", "[interlocks.inputs]\ntool_up = 7\n", {"config.range", "p.toml", 16, 11}},
        BadCase{"SlopeOfAWrongPitch",
                "[axis.x.compensation]\ninterval = 10\nerrors = [0, 0.5]\n",
                {"config.range", "p.toml", 17, 10}},
        BadCase{"TablesOfDifferentLengths",
                "[axis.x.compensation]\ninterval = 10\nforward = [0, 0.001]\nreverse = [0]\n",
                {"config.range", "p.toml", 18, 11}},
        BadCase{"TableWithoutInterval",
                "[axis.x.compensation]\nerrors = [0, 0.001]\n",
                {"config.missing-key", "p.toml", 15, 1}},
        BadCase{"CompensationOfAHandAxis",
                "[axis.z.compensation]\nbacklash = 0.01\n",
                {"config.not-applicable", "p.toml", 15, 1}},
        BadCase{"TakeUpEatsTheAxis",
                "[axis.x.compensation]\nbacklash = 0.01\ntakeup_velocity = 40\n",
                {"config.range", "p.toml", 17, 19}},
        BadCase{"MidpointReturnsTheWrongWay",
                "[axis.x.homing]\nmethod = \"decel_midpoint\"\nsearch_velocity = -40\nreturn_velocity = -1\n"
                "latch_velocity = -0.5\noverrun = 10\n",
                {"config.homing", "p.toml", 18, 19}},
        BadCase{"MidpointWithoutOverrun",
                "[axis.x.homing]\nmethod = \"decel_midpoint\"\nsearch_velocity = -40\nreturn_velocity = 1\n"
                "latch_velocity = 0.5\n",
                {"config.missing-key", "p.toml", 15, 1}},
        BadCase{"MidpointNeedsAnAnalogSensor",
                "[axis.x.homing]\nmethod = \"decel_midpoint\"\nsearch_velocity = -40\nreturn_velocity = 1\n"
                "latch_velocity = 0.5\noverrun = 10\n[axis.x.switches]\nhome = [-2, 2]\ndecel = [-inf, 8]\n",
                {"config.homing", "p.toml", 15, 1}},
        BadCase{"HandAxisCannotSearch",
                "[axis.z.homing]\nmethod = \"switch\"\nsearch_velocity = 5\nlatch_velocity = 1\n",
                {"config.homing", "p.toml", 15, 1}},
        BadCase{"PullOutOnAServo",
                "[axis.y]\nmax_velocity = 50\nmax_acceleration = 300\nmin_limit = 0\nmax_limit = "
                "1\n[axis.y.sim]\n"
                "pullout_force_n = 100\n",
                {"config.not-applicable", "p.toml", 21, 19}},
        BadCase{"StepperMassWithoutPullOut",
                "[axis.x.sim]\nmass_kg = 100\n",
                {"config.not-applicable", "p.toml", 16, 11}},
        BadCase{"HandwheelSteps", "[handwheel]\nsteps = [0.01, -1]\n", {"config.range", "p.toml", 16, 9}}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace opencnc::config
