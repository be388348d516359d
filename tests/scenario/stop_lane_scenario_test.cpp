// SPDX-License-Identifier: GPL-3.0-or-later
// Stops never wait: with the tick running by itself (as on a real-time thread or in HAL) and the
// controller busy with a long request — the preflight of an endless program, a cycle start's
// re-check, a run-from-line scan, a tool-store write waiting for the database's lock, the
// breakpoint journal writing after a power failure, a feature stuck on a slow disk — an e-stop,
// feed hold, abort or machine off acts in the very next servo period. The periods are counted
// exactly: this thread ticks the servo, the controller runs on threads of its own.
#include <gtest/gtest.h>

#include <sqlite3.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>

#include "../control/test_profiles.hpp"
#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/run_from_line/run_from_line.hpp"
#include "opencnc/toolguard/tool_guard.hpp"
#include "opencnc/tools/tool_text.hpp"
#include "scenario.hpp"
#include "temp_db.hpp"

namespace opencnc::controller::test {
namespace {

using namespace std::chrono_literals;

/// The simulated machine, with the outputs of the last period kept for the test's thread.
class KeptOutputs final : public machine::MachineIO {
 public:
  explicit KeptOutputs(machine::SimMachine& sim) : sim_(sim) {}
  machine::MachineCapabilities capabilities() const noexcept override { return sim_.capabilities(); }
  void read(machine::MachineInputs& in) noexcept override { sim_.read(in); }
  void write(const machine::MachineOutputs& out) noexcept override {
    last_ = out;
    sim_.write(out);
  }
  const machine::MachineOutputs& last() const { return last_; }

 private:
  machine::SimMachine& sim_;
  machine::MachineOutputs last_{};
};

/// A machine whose tick runs by itself: the controller is serviced on a thread of its own (its
/// long work on another), while the test's thread ticks the servo and counts the periods.
class SplitRig {
 public:
  SplitRig(const config::MachineProfile& profile, std::shared_ptr<ProgramSource> source)
      : channels_(std::make_unique<control::ServoChannels>()),
        sim_(config::sim_machine_config(profile)),
        io_(sim_),
        servo_(servo_config(profile), *channels_, io_),
        controller_(profile, *channels_, std::move(source), ControllerOptions{.long_work_on_thread = true}) {
    thread_ = std::thread([this] {
      while (!stop_.load()) {
        controller_.service();
        std::this_thread::sleep_for(100us);
      }
    });
  }
  ~SplitRig() {
    stop_ = true;
    thread_.join();
  }

  void tick() { servo_.tick(); }
  /// Ticks (at about a tenth of real time) until `done`; false after 60 s of wall time.
  template <typename F>
  bool until(F done) {
    const auto give_up = std::chrono::steady_clock::now() + 60s;
    while (!done()) {
      if (std::chrono::steady_clock::now() > give_up) return false;
      tick();
      std::this_thread::sleep_for(20us);
    }
    return true;
  }
  void ticks(int n) {
    for (int i = 0; i < n; ++i) {
      tick();
      std::this_thread::sleep_for(20us);
    }
  }
  Outcome ask(Request r) {
    const std::uint64_t id = controller_.submit(std::move(r));
    std::optional<Outcome> o;
    EXPECT_TRUE(until([&] { return (o = controller_.outcome(id)).has_value(); }));
    return o.value_or(Outcome{false, control::Refusal::Busy, "no answer", {}});
  }
  void must(Request r) {
    const std::string name = r.name();
    const Outcome o = ask(std::move(r));
    ASSERT_TRUE(o.accepted) << name << ": " << o.message;
  }

  /// Sends `stop` between two periods and ticks until the tick has applied it: the periods that
  /// took (1: the next period).
  std::uint64_t periods_to_apply(Request stop) {
    const std::uint64_t id = controller_.submit(std::move(stop));
    const std::uint64_t sent = servo_.ticks();
    while (servo_.last_command_id() != id && servo_.ticks() - sent < 10000) tick();
    return servo_.ticks() - sent;
  }

  /// The e-stop's physical effect in the last period's outputs: no power, no spindle.
  bool everything_off() const {
    const machine::MachineOutputs& o = io_.last();
    bool any_enabled = false;
    for (const machine::JointOutputs& j : o.joints) any_enabled = any_enabled || j.enable;
    return !o.estop_release && !any_enabled && o.spindle.speed_rpm == 0;
  }

  Controller& controller() { return controller_; }
  control::Servo& servo() { return servo_; }
  machine::SimMachine& sim() { return sim_; }
  const machine::MachineOutputs& outputs() const { return io_.last(); }

 private:
  std::unique_ptr<control::ServoChannels> channels_;
  machine::SimMachine sim_;
  KeptOutputs io_;
  control::Servo servo_;
  Controller controller_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::shared_ptr<GcodeProgramSource> source_for(const config::MachineProfile& p) {
  Diagnostics d;
  return features::machine_setup(p, d)->source();
}

/// Machine on with the spindle at 3000 rpm, then Auto mode.
void spindle_running(SplitRig& r) {
  r.must(Request::simple(control::CommandKind::MachineOn));
  r.must(Request::set_mode(control::Mode::Manual));
  r.must(Request::spindle_on(3000, true));
  ASSERT_TRUE(r.until([&] { return r.outputs().spindle.speed_rpm == 3000; }));
  r.must(Request::set_mode(control::Mode::Auto));
}

/// The reproduction: an endless moving loop (refused only by the preflight's bounds).
constexpr const char* kEndless = "G21 G90 F1000\no1 while [1]\nG1 X1\nG1 X0\no1 endwhile\nM2\n";

/// A program whose check takes a while: 200,000 moves in a loop.
constexpr const char* kLong =
    "G21 G90 F3000\n#1 = 0\no1 while [#1 LT 100000]\nG1 X1\nG1 X0\n#1 = [#1 + 1]\no1 endwhile\nG1 Y5\nM2\n";

TEST(StopLane, AnEStopActsInTheNextPeriodWhileAnEndlessProgramIsChecked) {
  TempProgram p("endless.ngc", kEndless);
  SplitRig r(control::test::mill(), source_for(control::test::mill()));
  spindle_running(r);
  const std::uint64_t open = r.controller().submit(Request::open(p.path()));
  r.ticks(20);  // the controller takes the open and checks the program on its task thread
  EXPECT_EQ(r.periods_to_apply(Request::simple(control::CommandKind::EStop)), 1u);
  EXPECT_EQ(r.servo().state(), control::State::EStopped);
  EXPECT_TRUE(r.everything_off());
  // The e-stop cancelled the check (an endless program is never answered before it): nothing opened.
  std::optional<Outcome> o;
  ASSERT_TRUE(r.until([&] { return (o = r.controller().outcome(open)).has_value(); }));
  EXPECT_EQ(o->refusal, control::Refusal::Superseded) << o->message;
  EXPECT_FALSE(r.controller().open_program());
}

TEST(StopLane, AnAbortActsInTheNextPeriodWhileACycleStartChecksTheProgramAgain) {
  TempProgram p("part.ngc", "G21 G90 F600\nG1 X1\nM2\n");
  SplitRig r(control::test::mill(), source_for(control::test::mill()));
  spindle_running(r);
  r.must(Request::open(p.path()));
  std::ofstream(p.path()) << kLong;  // changed since its check: the cycle start checks it again
  const Pose before = r.controller().status().servo.commanded;
  const std::uint64_t start = r.controller().submit(Request::simple(control::CommandKind::CycleStart));
  r.ticks(20);
  EXPECT_EQ(r.periods_to_apply(Request::simple(control::CommandKind::Abort)), 1u);
  std::optional<Outcome> o;
  ASSERT_TRUE(r.until([&] { return (o = r.controller().outcome(start)).has_value(); }));
  EXPECT_EQ(o->refusal, control::Refusal::Superseded) << o->message;
  r.ticks(50);
  EXPECT_FALSE(r.controller().status().run_active);
  EXPECT_EQ(r.controller().status().servo.commanded, before) << "the aborted start moved the machine";
}

TEST(StopLane, AnEStopActsInTheNextPeriodWhileRunFromLineScans) {
  TempProgram p("part.ngc", kLong);
  const config::MachineProfile profile = control::test::mill();
  Diagnostics d;
  auto machine = features::machine_setup(profile, d);  // run from line, as every front end sets it up
  ASSERT_TRUE(machine);
  SplitRig r(profile, machine->source());
  machine->install(r.controller());
  spindle_running(r);
  r.must(Request::open(p.path()));
  const std::uint64_t scan =
      r.controller().submit(Request::feature("run-from-line", "start", run_from_line::RunFromLineArgs{8}));
  r.ticks(5);
  EXPECT_EQ(r.periods_to_apply(Request::simple(control::CommandKind::EStop)), 1u);
  EXPECT_TRUE(r.everything_off());
  ASSERT_TRUE(r.until([&] { return r.controller().outcome(scan).has_value(); }));
  r.ticks(50);
  EXPECT_FALSE(r.controller().status().run_active) << "run from line started after the e-stop";
}

TEST(StopLane, AnEStopActsInTheNextPeriodWhileTheToolStoreWaitsForItsLock) {
  store::test::TempDb db;
  std::string error;
  {
    auto store = store::ToolStore::open(db.path(), &error);
    ASSERT_TRUE(store) << error;
    std::string text;
    ASSERT_TRUE(read_file(std::string(OPENCNC_SOURCE_DIR) + "/configs/hmc-toolcheck.tbl", text, nullptr));
    Diagnostics d;
    const auto set = tools::from_linuxcnc(tools::ToolTable::parse(text, "hmc-toolcheck.tbl", d), "hmc", d);
    ASSERT_TRUE(set && store->write(*set, "test", "import", &error)) << error;
  }
  const std::vector<std::string> sets = {"tool_guard.store=\"" + db.path() + "\""};
  const config::ProfileLoad load =
      config::load_profile(std::string(OPENCNC_SOURCE_DIR) + "/configs/hmc-toolcheck.toml", sets);
  ASSERT_TRUE(load.ok());
  Diagnostics d;
  auto machine = features::machine_setup(*load.profile, d);  // the guard, as every front end sets it up
  ASSERT_TRUE(machine) << (d.items().empty() ? "" : d.items()[0].format());
  SplitRig r(*load.profile, machine->source());
  machine->install(r.controller());
  spindle_running(r);
  // Another writer holds the database: the guard's backup waits for it (SQLite's busy wait).
  sqlite3* other = nullptr;
  ASSERT_EQ(sqlite3_open(db.path().c_str(), &other), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(other, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);
  const std::uint64_t accept = r.controller().submit(Request::feature("tool-guard", "accept"));
  r.ticks(20);
  EXPECT_EQ(r.periods_to_apply(Request::simple(control::CommandKind::EStop)), 1u);
  EXPECT_TRUE(r.everything_off());
  EXPECT_FALSE(r.controller().outcome(accept)) << "the write did not wait for the lock";
  sqlite3_exec(other, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(other);
  std::optional<Outcome> o;
  ASSERT_TRUE(r.until([&] { return (o = r.controller().outcome(accept)).has_value(); }));
  EXPECT_TRUE(o->accepted) << o->message;
}

TEST(StopLane, AnEStopActsInTheNextPeriodWhileTheJournalWritesTheBreakpoint) {
  TempProgram p("job.ngc",
                "G21 G90 G94 G17 G40 G49\nG64 P0.005\nG0 X-0.5\nG0 Z-10 C0\nM171 P600\nG1 X0.1 F60\n"
                "G1 Z310 F3000\nG1 X-0.4 F60\nG0 Z-10\nM175\nM2\n");
  const config::MachineProfile profile =
      control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml"));
  auto source = source_for(profile);
  SplitRig r(profile, source);
  const auto dir = std::filesystem::path(p.path()).parent_path() / "journal";
  std::filesystem::create_directories(dir);
  std::string error;
  auto journal = recovery::BreakpointJournal::open(dir.string(), source, &error);
  ASSERT_TRUE(journal) << error;
  ASSERT_TRUE(r.controller().add_feature(journal, ObserverOptions{profile.servo_period_s, true}));
  r.must(Request::simple(control::CommandKind::MachineOn));
  r.must(Request::set_mode(control::Mode::Auto));
  r.must(Request::open(p.path()));
  r.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(r.until([&] { return r.controller().status().servo.time_s >= 3.2; }));
  r.sim().set_mains_ok(false);  // the power-fail stop: the journal writes the record of the signal
  r.ticks(2);
  // The clock is the test's: the axes stand still in time while the journal catches up.
  const auto give_up = std::chrono::steady_clock::now() + 60s;
  while (!journal->last_written() && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(1ms);
  ASSERT_TRUE(journal->last_written()) << "the journal wrote no record";
  ASSERT_NE(r.servo().state(), control::State::Faulted)
      << "the axes came to rest before the e-stop could be sent";
  // The axes still stopping on the helix, the journal's writer about to write the at-rest record.
  EXPECT_EQ(r.periods_to_apply(Request::simple(control::CommandKind::EStop)), 1u);
  EXPECT_TRUE(r.everything_off());
}

/// A feature that holds the controller's thread inside its request until released: a slow disk,
/// a stuck database, anything a feature may wait for.
class StuckFeature final : public Feature {
 public:
  std::string_view name() const override { return "stuck"; }
  Outcome handle(const requests::Feature&, FeatureHost&) override {
    std::unique_lock lock(mutex_);
    inside_ = true;
    changed_.notify_all();
    changed_.wait(lock, [this] { return released_; });
    return Outcome{true, control::Refusal::None, "released", {}};
  }
  void wait_inside() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return inside_; });
  }
  void release() {
    std::lock_guard lock(mutex_);
    released_ = true;
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  bool inside_ = false, released_ = false;
};

struct StopCase {
  control::CommandKind stop;
  control::State after;  ///< the servo's state the period after
};

class StopsWhileStuck : public ::testing::TestWithParam<StopCase> {};

TEST_P(StopsWhileStuck, TheStopActsInTheNextPeriod) {
  TempProgram p("part.ngc", "G21 G90 M3 S3000\nG1 X150 F1200\nM2\n");
  SplitRig r(control::test::mill(), source_for(control::test::mill()));
  auto stuck = std::make_shared<StuckFeature>();
  ASSERT_TRUE(r.controller().add_feature(stuck));
  r.must(Request::simple(control::CommandKind::MachineOn));
  r.must(Request::set_mode(control::Mode::Auto));
  r.must(Request::open(p.path()));
  r.must(Request::simple(control::CommandKind::CycleStart));
  ASSERT_TRUE(r.until(
      [&] { return r.servo().state() == control::State::Running && r.outputs().spindle.speed_rpm == 3000; }));
  r.ticks(300);
  const std::uint64_t id = r.controller().submit(Request::feature("stuck", "wait"));
  stuck->wait_inside();  // the controller's thread is held from here on
  EXPECT_EQ(r.periods_to_apply(Request::simple(GetParam().stop)), 1u);
  EXPECT_EQ(r.servo().state(), GetParam().after);
  if (GetParam().stop == control::CommandKind::EStop) {
    EXPECT_TRUE(r.everything_off());
  }
  stuck->release();
  ASSERT_TRUE(r.until([&] { return r.controller().outcome(id).has_value(); }));
}

INSTANTIATE_TEST_SUITE_P(EveryStop, StopsWhileStuck,
                         ::testing::Values(StopCase{control::CommandKind::EStop, control::State::EStopped},
                                           StopCase{control::CommandKind::MachineOff, control::State::Off},
                                           StopCase{control::CommandKind::FeedHold, control::State::Held},
                                           StopCase{control::CommandKind::Abort, control::State::Idle}),
                         [](const ::testing::TestParamInfo<StopCase>& p) {
                           switch (p.param.stop) {
                             case control::CommandKind::EStop:
                               return std::string("EStop");
                             case control::CommandKind::MachineOff:
                               return std::string("MachineOff");
                             case control::CommandKind::FeedHold:
                               return std::string("FeedHold");
                             default:
                               return std::string("Abort");
                           }
                         });

}  // namespace
}  // namespace opencnc::controller::test
