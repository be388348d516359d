// SPDX-License-Identifier: GPL-3.0-or-later
// Scenario harness: the whole controller (G-code source, controller, servo, simulated machine)
// in virtual time, with the run's trace recorded, and G-code programs written to a temp folder.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/run_recorder.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

namespace opencnc::controller::test {

inline std::ostream& operator<<(std::ostream& os, control::State s) {
  return os << to_string(s);
}

/// A G-code file in a folder of its own; removed with the object.
class TempProgram {
 public:
  TempProgram(const std::string& name, const std::string& text) {
    dir_ = std::filesystem::temp_directory_path() /
           ("opencnc-scenario-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / name).string();
    std::ofstream(path_) << text;
  }
  ~TempProgram() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::filesystem::path dir_;
  std::string path_;
};

/// Every servo period's sample, and the report of the program runs among them.
class SampleKeeper final : public ControllerObserver {
 public:
  /// `output_limits`: what the drives' commands (with compensation) must stay within.
  SampleKeeper(const plan::MachineLimits& limits, const plan::MachineLimits& output_limits, double period_s)
      : limits_(limits), output_limits_(output_limits), period_s_(period_s) {
    forget();
  }
  void on_trace(const control::TraceSample& s, const TraceContext& c) override {
    samples_.push_back(s);
    if (s.activity == control::Activity::Program) recorder_->add(s, c);
  }
  void forget() {
    samples_.clear();
    recorder_ = std::make_unique<RunRecorder>(limits_, period_s_, &output_limits_);
  }
  const std::vector<control::TraceSample>& samples() const { return samples_; }
  RunReport report() const { return recorder_->report(); }

 private:
  plan::MachineLimits limits_, output_limits_;
  double period_s_;
  std::vector<control::TraceSample> samples_;
  std::unique_ptr<RunRecorder> recorder_;
};

class Scenario {
 public:
  /// The machine as its features set it up (features::machine_setup), as every front end does.
  explicit Scenario(const config::MachineProfile& profile) : profile_(profile) {
    Diagnostics d;
    machine_ = features::machine_setup(profile, d);
    EXPECT_TRUE(machine_ != nullptr) << (d.items().empty() ? "" : d.items()[0].format());
    rig_ = std::make_unique<SimRig>(profile, *machine_);
    start();
  }
  /// With a program source of the test's own (a tool table in memory, code modules) and no feature.
  Scenario(const config::MachineProfile& profile, std::shared_ptr<ProgramSource> source) : profile_(profile) {
    rig_ = std::make_unique<SimRig>(profile, std::move(source));
    start();
  }

  Outcome ask(Request r) {
    const Outcome o = rig_->request(std::move(r));
    std::string why = o.message;
    for (const auto& d : o.diagnostics.items()) why += "\n  " + d.format();
    last_message_ = why;
    return o;
  }
  /// Asserting form: the request must be accepted.
  void must(Request r) {
    const std::string name = r.name();
    const Outcome o = ask(std::move(r));
    ASSERT_TRUE(o.accepted) << name << ": " << last_message_;
  }
  void on(control::Mode m) {
    must(Request::simple(control::CommandKind::MachineOn));
    must(Request::set_mode(m));
  }

  /// Ticks until `done` (checked after each), recording the trace; whether it held.
  template <typename F>
  bool until(F done, std::uint64_t max_ticks) {
    for (std::uint64_t i = 0; i < max_ticks; ++i) {
      rig_->step();
      if (done()) return true;
    }
    return false;
  }
  void ticks(std::uint64_t n) {
    until([] { return false; }, n);
  }
  /// Opens `path` and runs it to its end (or `max_ticks`).
  bool run_file(const std::string& path, std::uint64_t max_ticks = 200000) {
    must(Request::open(path));
    return start_and_finish(max_ticks);
  }
  bool start_and_finish(std::uint64_t max_ticks = 200000) {
    const std::uint64_t finished = status().runs_finished;
    keeper_->forget();
    must(Request::simple(control::CommandKind::CycleStart));
    return until([&] { return !status().run_active && status().runs_finished > finished; }, max_ticks);
  }
  bool idle(std::uint64_t max_ticks = 100000) {
    return until([&] { return status().servo.state == control::State::Idle && !status().run_active; },
                 max_ticks);
  }

  /// The report of the program runs since the last start_and_finish() or forget_samples().
  RunReport report() const { return keeper_->report(); }

  ControllerStatus status() const { return rig_->status(); }
  SimRig& rig() { return *rig_; }
  /// The machine's features as set up (the first constructor).
  MachineSetup& machine() { return *machine_; }
  machine::SimMachine& sim() { return rig_->machine(); }
  const std::vector<control::TraceSample>& samples() const { return keeper_->samples(); }
  void forget_samples() { keeper_->forget(); }
  const std::string& message() const { return last_message_; }

 private:
  void start() {
    keeper_ = std::make_shared<SampleKeeper>(machine_limits(profile_), axis_limits(profile_),
                                             profile_.servo_period_s);
    rig_->controller().attach(keeper_, ObserverOptions{0, true});
    rig_->step();  // the observer is attached from here on
  }

  config::MachineProfile profile_;
  std::unique_ptr<MachineSetup> machine_;  ///< the features' set-up (null with a source of the test's own)
  std::unique_ptr<SimRig> rig_;
  std::shared_ptr<SampleKeeper> keeper_;
  std::string last_message_;
};

}  // namespace opencnc::controller::test
