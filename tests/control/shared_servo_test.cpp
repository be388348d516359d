// SPDX-License-Identifier: GPL-3.0-or-later
// The servo tick over POSIX shared memory, in one process: the segment created as the HAL component
// creates it and attached a second time as the controller attaches it; the layout check, the
// set-up hand-over, and the heartbeat (a silent controller stops the machine within its limits).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "opencnc/control/shared_memory.hpp"
#include "opencnc/control/shared_servo.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/machine/sim_machine.hpp"
#include "test_profiles.hpp"

namespace opencnc::control::test {
namespace {

std::string segment_name(const char* what) {
  return "/opencnc-test-" + std::to_string(::getpid()) + "-" + what;
}

/// The simulated machine as a backend whose capabilities come with the set-up (the HAL pins' way).
class SimBackend final : public ConfigurableMachine {
 public:
  explicit SimBackend(const config::MachineProfile& p) : sim_(config::sim_machine_config(p)) {}
  machine::MachineCapabilities capabilities() const noexcept override { return caps_; }
  void read(machine::MachineInputs& in) noexcept override { sim_.read(in); }
  void write(const machine::MachineOutputs& out) noexcept override {
    last_ = out;
    sim_.write(out);
  }
  void set_capabilities(const machine::MachineCapabilities& caps) noexcept override { caps_ = caps; }
  const machine::MachineOutputs& last() const noexcept { return last_; }
  machine::SimMachine& sim() noexcept { return sim_; }

 private:
  machine::SimMachine sim_;
  machine::MachineCapabilities caps_{};
  machine::MachineOutputs last_{};
};

/// Component side (segment creator, host, machine) and controller side (its own mapping, the
/// controller, the heartbeat it beats while `beating`), stepped in one thread.
class SharedRig {
 public:
  explicit SharedRig(const config::MachineProfile& p, const char* name, std::uint32_t timeout_ticks = 50)
      : profile_(p), backend_(p) {
    std::string error;
    owner_ = SegmentMapping::create(segment_name(name), 1'000'000, timeout_ticks, error);
    EXPECT_TRUE(owner_) << error;
    host_ = std::make_unique<SharedServoHost>(owner_->segment(), backend_);
    attach();
  }
  /// A (new) controller process: maps the segment, drains what was left, hands its set-up over
  /// (`setup`, else the profile's).
  void attach(const SharedSetup* setup = nullptr) {
    std::string error;
    controller_.reset();
    mapping_ = SegmentMapping::attach(owner_->name(), error);
    ASSERT_TRUE(mapping_) << error;
    drain_stale_output(mapping_->segment());
    controller_ = std::make_unique<controller::Controller>(profile_, mapping_->segment().channels);
    const std::uint64_t g = setup ? offer_setup(mapping_->segment(), *setup)  // its bytes, padding too
                                  : offer_setup(mapping_->segment(), controller::shared_setup(profile_));
    for (int i = 0; i < 10 && !setup_taken(mapping_->segment(), g); ++i) step();
    ASSERT_TRUE(setup_taken(mapping_->segment(), g));
  }
  void step() {
    if (controller_) controller_->service();
    if (beating) mapping_->segment().header.heartbeat.fetch_add(1);
    host_->tick();
  }
  bool until(const std::function<bool()>& done, int max) {
    for (int i = 0; i < max; ++i) {
      step();
      if (done()) return true;
    }
    return false;
  }
  controller::Outcome ask(controller::Request r) {
    const std::uint64_t id = controller_->submit(std::move(r));
    std::optional<controller::Outcome> o;
    until([&] { return (o = controller_->outcome(id)).has_value(); }, 1000);
    return o.value_or(controller::Outcome{});
  }
  ServoStatus status() const { return controller_->status().servo; }

  bool beating = true;
  config::MachineProfile profile_;
  SimBackend backend_;
  std::unique_ptr<SegmentMapping> owner_, mapping_;
  std::unique_ptr<SharedServoHost> host_;
  std::unique_ptr<controller::Controller> controller_;
};

TEST(SegmentMapping, RefusesAForeignOrOtherBuildSegment) {
  std::string error;
  EXPECT_FALSE(SegmentMapping::attach(segment_name("absent"), error));
  EXPECT_NE(error.find("is the HAL component opencnc_rt loaded"), std::string::npos) << error;
  error.clear();
  EXPECT_FALSE(SegmentMapping::create("no-slash", 1'000'000, 10, error));
  EXPECT_NE(error.find("must be one '/'"), std::string::npos) << error;

  error.clear();
  auto owner = SegmentMapping::create(segment_name("layout"), 1'000'000, 10, error);
  ASSERT_TRUE(owner) << error;
  EXPECT_EQ(owner->segment().header.layout_id, shared_layout_id());
  EXPECT_TRUE(SegmentMapping::attach(owner->name(), error)) << error;

  owner->segment().header.layout_id ^= 1;  // a tick of another build
  EXPECT_FALSE(SegmentMapping::attach(owner->name(), error));
  EXPECT_NE(error.find("built from another opencnc"), std::string::npos) << error;
  owner->segment().header.layout_id ^= 1;
  owner->segment().header.magic = 0;  // not ours
  error.clear();
  EXPECT_FALSE(SegmentMapping::attach(owner->name(), error));
  EXPECT_NE(error.find("is not an opencnc segment"), std::string::npos) << error;
}

// A restarted controller hands over the same set-up byte for byte (padding included), so the tick
// keeps its servo and the joints' homed state.
TEST(SharedSetup, IsTheSameBytesForTheSameProfile) {
  // The drill: pitch tables, backlash; the EDM: its conditions (padding after flags and small
  // integers, which ASan's filled allocations show).
  const config::MachineProfile edm = loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/edm-5axis.toml"));
  for (const config::MachineProfile& p : {mill(), drill(), edm}) {
    const SharedSetup a = controller::shared_setup(p), b = controller::shared_setup(p);
    const auto* pa = reinterpret_cast<const unsigned char*>(&a);
    const auto* pb = reinterpret_cast<const unsigned char*>(&b);
    for (std::size_t i = 0; i < sizeof a; ++i) ASSERT_EQ(pa[i], pb[i]) << p.name << " byte " << i;
  }
}

TEST(SharedServoHost, SafeOutputsUntilASetupIsTaken) {
  const config::MachineProfile p = mill();
  std::string error;
  auto owner = SegmentMapping::create(segment_name("safe"), 1'000'000, 10, error);
  ASSERT_TRUE(owner) << error;
  SimBackend backend(p);
  SharedServoHost host(owner->segment(), backend);
  for (int i = 0; i < 5; ++i) host.tick();
  EXPECT_FALSE(host.running());
  EXPECT_FALSE(backend.last().estop_release);
  for (const auto& j : backend.last().joints) EXPECT_FALSE(j.enable);
  EXPECT_EQ(owner->segment().header.ticks.load(), 5u);
  const std::uint64_t g = offer_setup(owner->segment(), controller::shared_setup(p));
  host.tick();
  EXPECT_TRUE(setup_taken(owner->segment(), g));
  EXPECT_TRUE(host.running());
  EXPECT_GT(backend.capabilities().joint_count, 0);
}

TEST(SharedServoHost, AControllerOverSharedMemoryJogsTheMachine) {
  SharedRig rig(mill(), "jog");
  ASSERT_TRUE(rig.ask(controller::Request::simple(CommandKind::MachineOn)).accepted);
  ASSERT_TRUE(rig.ask(controller::Request::set_mode(Mode::Manual)).accepted);
  const double x0 = rig.status().commanded[0];
  ASSERT_TRUE(rig.ask(controller::Request::jog(Axis::X, 20)).accepted);
  rig.until([] { return false; }, 500);
  EXPECT_GT(rig.status().commanded[0], x0 + 5);
  EXPECT_TRUE(rig.status().drives_enabled);
  ASSERT_TRUE(rig.ask(controller::Request::jog_stop()).accepted);
  EXPECT_TRUE(rig.until([&] { return rig.status().state == State::Idle; }, 500));
}

// The controller process dies mid-jog: the tick sees no heartbeat for the timeout, brings the
// joint to rest within its acceleration, faults (power loss path) and disables the drives; a new
// controller attaches to the same tick (same set-up: the servo and its state stay) and resets.
TEST(SharedServoHost, ASilentControllerStopsTheMachineAndANewOneTakesOver) {
  SharedRig rig(mill(), "heartbeat", 50);
  ASSERT_TRUE(rig.ask(controller::Request::simple(CommandKind::MachineOn)).accepted);
  ASSERT_TRUE(rig.ask(controller::Request::set_mode(Mode::Manual)).accepted);
  ASSERT_TRUE(rig.ask(controller::Request::jog(Axis::X, 30)).accepted);
  rig.until([] { return false; }, 400);
  const std::uint64_t built_before = rig.host_->servos_built();
  ASSERT_EQ(built_before, 1u);
  ASSERT_GT(rig.backend_.sim().joint(0).velocity(), 25.0);

  rig.beating = false;
  rig.controller_.reset();  // the process is gone: nothing services the channels any more
  const double accel = rig.profile_.axes[0].max_acceleration;
  double last = rig.backend_.sim().joint(0).motor_position();
  int ticks = 0, stopped_at = -1;
  for (; ticks < 2000; ++ticks) {
    rig.host_->tick();
    const double pos = rig.backend_.sim().joint(0).motor_position();
    if (stopped_at < 0 && std::fabs(pos - last) < 1e-9 && ticks > 50) stopped_at = ticks;
    last = pos;
  }
  EXPECT_EQ(rig.owner_->segment().header.heartbeat_losses.load(), 1u);
  EXPECT_FALSE(rig.owner_->segment().header.controller_alive.load());
  ASSERT_GE(stopped_at, 50) << "the joint did not come to rest";
  // Within the timeout plus the time to stop at the joint's acceleration (and a margin of 20 %).
  EXPECT_LE(stopped_at, 50 + static_cast<int>(1.2 * 1000 * 30 / accel) + 5);
  for (const auto& j : rig.backend_.last().joints) EXPECT_FALSE(j.enable);

  rig.beating = true;
  rig.attach();
  EXPECT_EQ(rig.host_->servos_built(), built_before);  // same set-up: the servo (and its state) stayed
  rig.until([&] { return rig.status().state == State::Faulted; }, 10);
  EXPECT_EQ(rig.status().fault.kind, FaultKind::PowerLoss);
  ASSERT_TRUE(rig.ask(controller::Request::simple(CommandKind::Reset)).accepted);
  EXPECT_TRUE(rig.ask(controller::Request::simple(CommandKind::MachineOn)).accepted);
}

/// The drill's profile and tool table copied to a directory of this test's own (profile edits
/// write the file); removed with the object.
struct DrillCopy {
  explicit DrillCopy(const char* what)
      : dir(std::filesystem::temp_directory_path() /
            ("opencnc-" + std::string(what) + "-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir);
    for (const char* f : {"drill-retrofit.toml", "drill-retrofit.tbl"})
      std::filesystem::copy_file(std::filesystem::path(OPENCNC_SOURCE_DIR "/configs") / f, dir / f,
                                 std::filesystem::copy_options::overwrite_existing);
  }
  ~DrillCopy() { std::filesystem::remove_all(dir); }
  config::MachineProfile profile() const {
    return loaded(config::load_profile((dir / "drill-retrofit.toml").string()));
  }
  std::filesystem::path dir;
};

// The tick outlives a controller that left Y on pitch buffer 0 with the profile's own table (three
// edits: buffers 0, 1, 0, the last back to the file's first values) and whose last act was a stage
// the tick refused. A new controller loads that file: the same set-up, so the servo and its table
// stay. Its edit goes into buffer 1, never into the buffer the lookup reads, and is not refused for
// what the dead one staged.
TEST(SharedServoHost, ANewControllerNeverWritesThePitchBufferTheTickReads) {
  const DrillCopy copy("pitch-reattach");
  SharedRig rig(copy.profile(), "pitch-reattach");
  PitchTableArea& area = rig.owner_->segment().channels.pitch_tables;
  EXPECT_EQ(area.reading[1].index.load(), -1);  // a servo just built reads its configuration's table
  const auto forward = [](const char* fifth) {
    return std::string("[0, -0.002, -0.004, -0.0045, ") + fifth + ", -0.007, -0.009, -0.0105, -0.012]";
  };
  for (const char* fifth : {"-0.006", "-0.007", "-0.005"}) {
    const controller::Outcome o = rig.ask(
        controller::Request::edit_profile({{"axis.y.compensation.forward", forward(fifth)}}, "admin"));
    ASSERT_TRUE(o.accepted) << o.message;
  }
  ASSERT_EQ(area.reading[1].index.load(), 0);
  const motion::PitchTable in_use = area.joints[1][0];
  EXPECT_EQ(in_use.forward[4], -0.005);
  const std::uint64_t taken = rig.owner_->segment().header.setup_taken.load();

  // The dead controller's last act: a table the tick refuses (positions not increasing) staged in
  // buffer 1, no apply.
  area.joints[1][1] = in_use;
  area.joints[1][1].position[3] = area.joints[1][1].position[2];
  Command stale;
  stale.id = 99001;
  stale.kind = CommandKind::StagePitchTable;
  stale.axis = 1;
  stale.table_buffer = 1;
  ASSERT_TRUE(rig.owner_->segment().channels.commands.try_push(stale));
  rig.step();
  rig.controller_.reset();
  // The same set-up, byte for byte as the tick took it (shared_setup() leaves EdmConfig's padding
  // as the copies made it, so two calls may differ there under the sanitizers).
  const auto same = std::make_unique<SharedSetup>();
  std::memcpy(static_cast<void*>(same.get()), &rig.owner_->segment().setup, sizeof(SharedSetup));
  rig.profile_ = copy.profile();
  rig.attach(same.get());
  ASSERT_GT(rig.owner_->segment().header.setup_taken.load(), taken);
  ASSERT_EQ(area.reading[1].index.load(), 0) << "the set-up differs: the servo was rebuilt";

  const controller::Outcome o = rig.ask(
      controller::Request::edit_profile({{"axis.y.compensation.forward", forward("-0.008")}}, "admin"));
  ASSERT_TRUE(o.accepted) << o.message;
  EXPECT_EQ(area.reading[1].index.load(), 1);
  const Servo* servo = rig.host_->servo();
  EXPECT_EQ(&servo->compensation().pitch_table(1), &area.joints[1][1]);
  EXPECT_EQ(area.joints[1][1].forward[4], -0.008);
  EXPECT_EQ(std::memcmp(&area.joints[1][0], &in_use, sizeof in_use), 0) << "the table in use was written";

  // A stage naming the buffer the tick reads is refused, and the apply with it.
  Command own = stale;
  own.id = 99002;
  Command apply;
  apply.id = 99003;
  apply.kind = CommandKind::ApplyJointLimits;
  ASSERT_TRUE(rig.mapping_->segment().channels.commands.try_push(own) &&
              rig.mapping_->segment().channels.commands.try_push(apply));
  rig.until([&] { return rig.controller_->outcome(99003).has_value(); }, 10);
  ASSERT_TRUE(rig.controller_->outcome(99003).has_value());
  EXPECT_EQ(rig.controller_->outcome(99003)->refusal, Refusal::BadValue);
  EXPECT_EQ(area.reading[1].index.load(), 1);
}

}  // namespace
}  // namespace opencnc::control::test
