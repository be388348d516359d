// SPDX-License-Identifier: GPL-3.0-or-later
// Machine parameters changed through the controller (requests::EditProfile): only while nothing
// moves, the file written with only those lines changed, the planner's limits, the move checks
// and the tick's joint limits swapped together; a bad value changes nothing.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "../control/test_profiles.hpp"
#include "../support/drill_comp_file.hpp"
#include "opencnc/canon/program_builder.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/core/atomic_file.hpp"

namespace opencnc::controller::test {
namespace {

std::shared_ptr<const canon::Program> line_x(const Pose& from, double to, double feed_mm_min) {
  canon::ProgramBuilder b(AxisMask::from_letters("XYZ"), from);
  b.set_feed_rate(feed_mm_min);
  Pose end = from;
  end[Axis::X] = to;
  b.straight_feed(0, end);
  b.program_end();
  return std::make_shared<const canon::Program>(b.take());
}

class ProfileChange : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("opencnc-profile-change-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "mill.toml").string();
    ASSERT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml", original_, nullptr));
    ASSERT_TRUE(write_file_atomically(path_, original_, nullptr));
    std::filesystem::copy_file(OPENCNC_SOURCE_DIR "/configs/mill-3axis.tbl", dir_ / "mill-3axis.tbl",
                               std::filesystem::copy_options::overwrite_existing);
    rig_ = std::make_unique<SimRig>(control::test::loaded(config::load_profile(path_)));
    ASSERT_TRUE(rig_->request(Request::simple(control::CommandKind::MachineOn)).accepted);
  }
  void TearDown() override {
    rig_.reset();
    std::filesystem::remove_all(dir_);
  }
  Outcome edit(std::vector<config::ProfileKeyEdit> edits) {
    return rig_->request(Request::edit_profile(std::move(edits), "admin@test"));
  }
  std::string file() const {
    std::string s;
    read_file(path_, s, nullptr);
    return s;
  }
  bool idle() {
    return rig_->run_until(
        [&] { return rig_->status().servo.state == control::State::Idle && !rig_->status().run_active; },
        100000);
  }
  /// The fastest |velocity| of X while `ticks` periods run.
  double fastest_x(std::uint64_t ticks) {
    double v = 0;
    for (std::uint64_t i = 0; i < ticks; ++i) {
      rig_->step();
      v = std::max(v, std::fabs(rig_->status().servo.joints[0].velocity));
    }
    return v;
  }
  std::filesystem::path dir_;
  std::string path_, original_;
  std::unique_ptr<SimRig> rig_;
};

TEST_F(ProfileChange, AJogAfterTheChangeObeysTheNewMaximumAndTheFileKeepsEverythingElse) {
  const Outcome o = edit({{"axis.x.max_velocity", "20.0"}, {"axis.x.max_following_error", "0.4"}});
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_EQ(o.message, "axis.x.max_velocity 100.0 → 20.0; axis.x.max_following_error 0.5 → 0.4");
  std::string expected = original_;
  expected.replace(expected.find("max_velocity = 100.0"), 20, "max_velocity = 20.0");
  expected.replace(expected.find("max_following_error = 0.5"), 25, "max_following_error = 0.4");
  EXPECT_EQ(file(), expected);
  EXPECT_EQ(rig_->controller().profile().axes[0].max_velocity, 20.0);
  EXPECT_EQ(rig_->controller().current_profile().axes[0].max_velocity, 20.0);
  EXPECT_EQ(rig_->servo().config().joints[0].max_velocity, 20.0);
  EXPECT_EQ(rig_->servo().config().joints[0].max_following_error, 0.4);
  EXPECT_EQ(rig_->servo().config().joints[1].max_velocity, 100.0);
  ASSERT_TRUE(rig_->request(Request::jog(Axis::X, 90)).accepted);
  const double v = fastest_x(400);
  EXPECT_LE(v, 20.0 + 1e-9);
  EXPECT_GT(v, 19.99);
  rig_->request(Request::jog_stop());
  ASSERT_TRUE(idle());
  bool noted = false;
  EventCursor cursor(rig_->controller().events(), true);
  for (const ControllerEvent& e : cursor.next())
    noted |= e.kind == ControllerEventKind::Note && e.code == "control.profile" &&
             e.text.find("admin@test: machine parameters changed: axis.x.max_velocity 100.0 → 20.0") == 0;
  EXPECT_TRUE(noted);
}

TEST_F(ProfileChange, RefusedWhileAJogRunsAndNothingChanges) {
  ASSERT_TRUE(rig_->request(Request::jog(Axis::X, 50)).accepted);
  rig_->run(50);
  const Outcome o = edit({{"axis.x.max_velocity", "20.0"}});
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.refusal, control::Refusal::Busy);
  EXPECT_EQ(file(), original_);
  EXPECT_EQ(rig_->servo().config().joints[0].max_velocity, 100.0);
  EXPECT_EQ(rig_->controller().profile().axes[0].max_velocity, 100.0);
}

TEST_F(ProfileChange, TheTickRefusingTheApplyPutsTheFileAndTheLimitsBack) {
  // A jog queued in the same period as the change: the controller still sees the machine idle,
  // the tick runs the jog first and refuses the limits.
  rig_->controller().submit(Request::jog(Axis::X, 50));
  const Outcome o = edit({{"axis.x.max_velocity", "20.0"}});
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.refusal, control::Refusal::Busy) << o.message;
  EXPECT_EQ(o.message, "the machine would not take the new limits now: nothing changed");
  EXPECT_EQ(file(), original_);
  EXPECT_EQ(rig_->servo().config().joints[0].max_velocity, 100.0);
  EXPECT_EQ(rig_->controller().profile().axes[0].max_velocity, 100.0);
  EXPECT_EQ(rig_->controller().current_profile().axes[0].max_velocity, 100.0);
}

TEST_F(ProfileChange, AProgramMoveAfterTheChangeObeysTheNewLimit) {
  ASSERT_TRUE(rig_->request(Request::set_mode(control::Mode::Auto)).accepted);
  const Pose at = rig_->status().servo.commanded;
  ASSERT_TRUE(rig_->request(Request::open(line_x(at, 100, 6000), "line")).accepted);
  ASSERT_TRUE(edit({{"axis.x.max_velocity", "25.0"}}).accepted);
  ASSERT_TRUE(rig_->request(Request::simple(control::CommandKind::CycleStart)).accepted);
  double v = 0;
  ASSERT_TRUE(rig_->run_until(
      [&] {
        v = std::max(v, std::fabs(rig_->status().servo.joints[0].velocity));
        return rig_->status().servo.state == control::State::Idle && !rig_->status().run_active;
      },
      100000));
  EXPECT_LE(v, 25.0 + 1e-6);
  EXPECT_GT(v, 24.9);
  EXPECT_NEAR(rig_->status().servo.commanded[Axis::X], 100.0, 1e-9);
}

TEST_F(ProfileChange, NewSoftLimitsAreCheckedBeforeTheOpenProgramStartsAndWhereTheMachineStands) {
  ASSERT_TRUE(rig_->request(Request::set_mode(control::Mode::Auto)).accepted);
  const Pose at = rig_->status().servo.commanded;
  ASSERT_TRUE(rig_->request(Request::open(line_x(at, 100, 3000), "line")).accepted);
  ASSERT_TRUE(edit({{"axis.x.max_limit", "50.0"}}).accepted);
  const Outcome start = rig_->request(Request::simple(control::CommandKind::CycleStart));
  EXPECT_FALSE(start.accepted);
  EXPECT_EQ(start.refusal, control::Refusal::SoftLimit) << start.message;
  EXPECT_EQ(rig_->status().servo.commanded[Axis::X], at[Axis::X]);
  ASSERT_TRUE(rig_->request(Request::set_mode(control::Mode::Manual)).accepted);
  ASSERT_TRUE(rig_->request(Request::jog_by(Axis::X, 40, 50)).accepted);
  ASSERT_TRUE(idle());
  const Outcome outside = edit({{"axis.x.max_limit", "30.0"}});
  EXPECT_FALSE(outside.accepted);
  EXPECT_EQ(outside.refusal, control::Refusal::SoftLimit);
  EXPECT_EQ(outside.message,
            "X stands at 40.0000, outside the new soft limits -2000.0000 … 30.0000: move it inside first");
  EXPECT_EQ(rig_->servo().config().joints[0].max_limit, 50.0);
}

TEST_F(ProfileChange, ABadValueGetsTheProfilesMessageAndChangesNothing) {
  const Outcome o = edit({{"axis.y.max_acceleration", "-1.0"}});
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.refusal, control::Refusal::BadValue);
  ASSERT_FALSE(o.diagnostics.items().empty());
  EXPECT_EQ(o.diagnostics.items().front().file, path_);
  EXPECT_EQ(o.message.rfind("the profile refuses the change: " + path_ + ":", 0), 0u) << o.message;
  const Outcome text = edit({{"axis.y.max_acceleration", "\"fast\""}});
  EXPECT_FALSE(text.accepted);
  EXPECT_FALSE(text.diagnostics.items().empty());
  const Outcome key = edit({{"axis.y.homing.position", "3.0"}});
  EXPECT_FALSE(key.accepted);
  EXPECT_NE(key.message.find("not a parameter that can be changed here"), std::string::npos);
  EXPECT_EQ(file(), original_);
  EXPECT_EQ(rig_->servo().config().joints[1].max_acceleration, 1000.0);
  EXPECT_EQ(rig_->controller().profile().axes[1].max_acceleration, 1000.0);
}

TEST(ServoLimits, AStagedSetAppliesWhileIdleAndABadStageRefusesTheApply) {
  SimRig rig(control::test::mill());
  ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
  auto send = [&](control::CommandKind k, int joint, control::JointLimits l) {
    control::Command c;
    c.id = 9000 + static_cast<std::uint64_t>(rig.ticks());
    c.kind = k;
    c.axis = static_cast<std::int8_t>(joint);
    c.limits = l;
    EXPECT_TRUE(rig.channels().commands.try_push(c));
    return c.id;
  };
  const control::JointLimits slow{10, 100, -5, 5, 0.2, 10};
  send(control::CommandKind::StageJointLimits, 1, {10, 100, 5, -5, 0.2, 10});  // min above max
  const std::uint64_t bad = send(control::CommandKind::ApplyJointLimits, -1, {});
  rig.run(3);
  ASSERT_TRUE(rig.controller().outcome(bad).has_value());
  EXPECT_EQ(rig.controller().outcome(bad)->refusal, control::Refusal::BadValue);
  EXPECT_EQ(rig.servo().config().joints[1].max_velocity, 100.0);
  send(control::CommandKind::StageJointLimits, 1, slow);
  const std::uint64_t good = send(control::CommandKind::ApplyJointLimits, -1, {});
  rig.run(3);
  EXPECT_TRUE(rig.controller().outcome(good)->accepted);
  EXPECT_EQ(rig.servo().config().joints[1].max_limit, 5.0);
  EXPECT_EQ(rig.servo().config().joints[0].max_limit, 2000.0);
  const std::uint64_t none = send(control::CommandKind::ApplyJointLimits, -1, {});
  rig.run(3);
  EXPECT_EQ(rig.controller().outcome(none)->refusal, control::Refusal::NotApplicable);
}

}  // namespace
}  // namespace opencnc::controller::test

namespace opencnc::controller::test {
namespace {

// The drill's X has a pitch table with backlash: its backlash and take-up limits are editable, the
// tick's compensation takes the new ones, the planner's reserve follows the new take-up limits.
TEST(ProfileChangeCompensation, BacklashAndTakeUpLimitsReachTheTickAndTheReserve) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("opencnc-comp-change-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* f : {"drill-retrofit.toml", "drill-retrofit.tbl"})
    std::filesystem::copy_file(std::filesystem::path(OPENCNC_SOURCE_DIR "/configs") / f, dir / f,
                               std::filesystem::copy_options::overwrite_existing);
  const std::string path = (dir / "drill-retrofit.toml").string();
  std::string original;
  ASSERT_TRUE(read_file(path, original, nullptr));
  {
    SimRig rig(control::test::loaded(config::load_profile(path)));
    const Outcome o = rig.request(Request::edit_profile(
        {{"axis.x.compensation.backlash", "0.05"}, {"axis.x.compensation.takeup_velocity", "4.0"}}));
    ASSERT_TRUE(o.accepted) << o.message;
    EXPECT_EQ(o.message,
              "axis.x.compensation.backlash 0.02 → 0.05; axis.x.compensation.takeup_velocity 2.0 → 4.0");
    const motion::JointCompensation& c = rig.servo().config().compensation.joints[0];
    EXPECT_EQ(c.backlash, 0.05);
    EXPECT_EQ(c.max_velocity, 4.0);
    const control::ServoConfig expected = controller::servo_config(rig.controller().profile());
    EXPECT_EQ(rig.servo().config().joints[0].max_velocity, expected.joints[0].max_velocity);
    EXPECT_LT(rig.servo().config().joints[0].max_velocity,
              rig.controller().profile().axes[0].max_velocity - 4.0);
    std::string text;
    ASSERT_TRUE(read_file(path, text, nullptr));
    std::string want = original;
    const std::size_t table = want.find("[axis.x.compensation]");
    want.replace(want.find("backlash = 0.02", table), 15, "backlash = 0.05");
    const std::size_t v = want.find("takeup_velocity = 2.0", table);
    want.replace(v, 21, "takeup_velocity = 4.0");
    EXPECT_EQ(text, want);
    const Outcome bad = rig.request(Request::edit_profile({{"axis.x.compensation.backlash", "-0.01"}}));
    EXPECT_FALSE(bad.accepted);
    EXPECT_EQ(rig.servo().config().compensation.joints[0].backlash, 0.05);
  }
  std::filesystem::remove_all(dir);
}

// X's pitch table through the controller: the message says what changed, the tick reads the new
// table from the channels' buffer; a table the loader refuses changes nothing; a table the tick
// cannot use (positions not increasing) makes the apply refuse.
TEST(ProfileChangeCompensation, APitchTableReachesTheTickAndABadOneChangesNothing) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("opencnc-pitch-change-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* f : {"drill-retrofit.toml", "drill-retrofit.tbl"})
    std::filesystem::copy_file(std::filesystem::path(OPENCNC_SOURCE_DIR "/configs") / f, dir / f,
                               std::filesystem::copy_options::overwrite_existing);
  const std::string path = (dir / "drill-retrofit.toml").string();
  {
    SimRig rig(control::test::loaded(config::load_profile(path)));
    const std::string y = "[0, -0.002, -0.004, -0.0045, -0.006, -0.007, -0.009, -0.0105, -0.012]";
    const Outcome o = rig.request(Request::edit_profile({{"axis.y.compensation.forward", y}}, "admin"));
    ASSERT_TRUE(o.accepted) << o.message;
    EXPECT_EQ(
        o.message,
        "axis.y.compensation.forward 9 points → 9 points, 1 changed (largest -0.005 → -0.006 at 200.0)");
    const motion::PitchTable& t = rig.servo().compensation().pitch_table(1);
    EXPECT_EQ(&t, &rig.channels().pitch_tables.joints[1][0]);
    EXPECT_EQ(t.forward[4], -0.006);
    EXPECT_EQ(rig.controller().profile().axes[1].compensation.forward[4], -0.006);
    std::string text;
    ASSERT_TRUE(read_file(path, text, nullptr));
    const Outcome steep =
        rig.request(Request::edit_profile({{"axis.y.compensation.forward", "[0, 0, 0, 0, 0, 0, 0, 0, 2]"}}));
    EXPECT_FALSE(steep.accepted);
    EXPECT_EQ(steep.refusal, control::Refusal::BadValue);
    EXPECT_NE(steep.message.find(path + ":"), std::string::npos) << steep.message;
    std::string after;
    ASSERT_TRUE(read_file(path, after, nullptr));
    EXPECT_EQ(after, text);
    EXPECT_EQ(&rig.servo().compensation().pitch_table(1), &t);
    // The tick checks what it is handed: positions not increasing.
    motion::PitchTable& bad = rig.channels().pitch_tables.joints[1][1];
    bad = t;
    bad.position[3] = bad.position[2];
    control::Command stage;
    stage.id = 77001;
    stage.kind = control::CommandKind::StagePitchTable;
    stage.axis = 1;
    stage.table_buffer = 1;
    control::Command apply;
    apply.id = 77002;
    apply.kind = control::CommandKind::ApplyJointLimits;
    ASSERT_TRUE(rig.channels().commands.try_push(stage) && rig.channels().commands.try_push(apply));
    rig.run(3);
    ASSERT_TRUE(rig.controller().outcome(77002).has_value());
    EXPECT_EQ(rig.controller().outcome(77002)->refusal, control::Refusal::BadValue);
    EXPECT_EQ(&rig.servo().compensation().pitch_table(1), &t);
  }
  std::filesystem::remove_all(dir);
}

// Y's table in a comp file: a jog queued in the same period makes the tick refuse, and the comp
// file is put back with the profile; at rest the change is written into the comp file and the
// tick reads the new table.
TEST(ProfileChangeCompensation, ACompFilesTableIsPutBackWhenTheTickRefusesAndWrittenWhenItTakesIt) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("opencnc-comp-change-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::string text;
  ASSERT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.toml", text, nullptr));
  const std::string path = (dir / "drill-retrofit.toml").string(),
                    comp = (dir / opencnc::test::kDrillYCompName).string();
  ASSERT_TRUE(write_file_atomically(path, opencnc::test::drill_with_y_comp_file(text), nullptr));
  ASSERT_TRUE(write_file_atomically(comp, opencnc::test::kDrillYComp, nullptr));
  std::filesystem::copy_file(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.tbl", dir / "drill-retrofit.tbl",
                             std::filesystem::copy_options::overwrite_existing);
  {
    SimRig rig(control::test::loaded(config::load_profile(path)));
    ASSERT_TRUE(rig.request(Request::simple(control::CommandKind::MachineOn)).accepted);
    const std::string forward = "[0, -0.002, -0.004, -0.0045, -0.006, -0.007, -0.009, -0.0105, -0.012]";
    rig.controller().submit(Request::jog(Axis::X, 5));
    const Outcome refused =
        rig.request(Request::edit_profile({{"axis.y.compensation.forward", forward}}, "admin"));
    ASSERT_FALSE(refused.accepted);
    EXPECT_EQ(refused.message, "the machine would not take the new limits now: nothing changed");
    std::string now;
    ASSERT_TRUE(read_file(comp, now, nullptr));
    EXPECT_EQ(now, opencnc::test::kDrillYComp);
    EXPECT_EQ(rig.controller().profile().axes[1].compensation.forward[4], -0.005);
    ASSERT_TRUE(rig.request(Request::jog_stop()).accepted);
    ASSERT_TRUE(rig.run_until([&] { return rig.status().servo.state == control::State::Idle; }, 10000));
    const Outcome o = rig.request(Request::edit_profile({{"axis.y.compensation.forward", forward}}, "admin"));
    ASSERT_TRUE(o.accepted) << o.message;
    ASSERT_TRUE(read_file(comp, now, nullptr));
    EXPECT_NE(now.find("200 199.994 200.01\n"), std::string::npos) << now;
    EXPECT_EQ(rig.servo().compensation().pitch_table(1).forward[4], -0.006);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace opencnc::controller::test
