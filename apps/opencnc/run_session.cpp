// SPDX-License-Identifier: GPL-3.0-or-later
// One program run for the command line, in virtual time (SimRig) or with a real-time servo thread.
#include "run_session.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <fmt/format.h>

#include "commands.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/control/clock.hpp"
#include "opencnc/control/servo.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "stop_signals.hpp"

namespace opencnc::cli {

namespace {

using control::CommandKind;
using control::Request;
using control::State;

void print(const Diagnostics& diags) {
  for (const Diagnostic& d : diags.items()) {
    fmt::print(stderr, "{}{}\n", d.format(), d.code.empty() ? "" : fmt::format(" [{}]", d.code));
  }
}

/// Moves the controller and the servo on: one servo period in virtual time, or one period of
/// the controller's loop while the real-time thread ticks on its own.
class Driver {
 public:
  virtual ~Driver() = default;
  virtual void advance() = 0;
  virtual control::Controller& controller() = 0;
  virtual control::ServoChannels& channels() = 0;
};

class VirtualDriver final : public Driver {
 public:
  VirtualDriver(const config::MachineProfile& p, std::shared_ptr<control::ProgramSource> s)
      : rig_(p, std::move(s)) {}
  void advance() override { rig_.step(); }
  control::Controller& controller() override { return rig_.controller(); }
  control::ServoChannels& channels() override { return rig_.channels(); }

 private:
  control::SimRig rig_;
};

class RealtimeDriver final : public Driver {
 public:
  RealtimeDriver(const config::MachineProfile& p, std::shared_ptr<control::ProgramSource> s)
      : channels_(std::make_unique<control::ServoChannels>()),
        sim_(std::make_unique<machine::SimMachine>(config::sim_machine_config(p))),
        servo_(std::make_unique<control::Servo>(control::servo_config(p), *channels_, *sim_)),
        controller_(std::make_unique<control::Controller>(p, *channels_, std::move(s))),
        period_(std::chrono::duration<double>(p.servo_period_s)),
        clock_(control::RealtimeClock::Options{static_cast<std::int64_t>(p.servo_period_s * 1e9 + 0.5)}) {}
  ~RealtimeDriver() override { clock_.stop(); }
  bool start() {
    const bool ok = clock_.start(*servo_);
    for (const std::string& w : clock_.warnings()) fmt::print(stderr, "warning: {}\n", w);
    return ok;
  }
  void advance() override {
    controller_->service();
    std::this_thread::sleep_for(period_);
  }
  control::Controller& controller() override { return *controller_; }
  control::ServoChannels& channels() override { return *channels_; }

 private:
  std::unique_ptr<control::ServoChannels> channels_;
  std::unique_ptr<machine::SimMachine> sim_;
  std::unique_ptr<control::Servo> servo_;
  std::unique_ptr<control::Controller> controller_;
  std::chrono::duration<double> period_;
  control::RealtimeClock clock_;
};

/// Submits `r` and advances until it is answered.
control::Outcome ask(Driver& d, Request r) {
  const std::uint64_t id = d.controller().submit(std::move(r));
  for (int i = 0; i < 100000; ++i) {
    d.advance();
    if (auto o = d.controller().outcome(id)) return *o;
  }
  return {false, control::Refusal::Busy, "the controller does not answer", {}};
}

bool must(Driver& d, Request r) {
  const CommandKind k = r.kind;
  const control::Outcome o = ask(d, std::move(r));
  print(o.diagnostics);
  if (!o.accepted) fmt::print(stderr, "error: {}: {}\n", control::to_string(k), o.message);
  return o.accepted;
}

void print_notes(control::Controller& c) {
  for (const control::Note& n : c.take_notes()) {
    if (n.severity == Severity::Note) {
      fmt::print(stderr, "message: {}\n", n.text);
    } else {
      fmt::print(stderr, "error: {}{}\n", n.text, n.code.empty() ? "" : fmt::format(" [{}]", n.code));
    }
  }
}

bool home_if_needed(Driver& d, const control::ServoConfig& sc) {
  if (!sc.homing_required) return true;
  if (!must(d, Request::set_mode(control::Mode::Manual)) || !must(d, Request::on_axis(CommandKind::Home, -1)))
    return false;
  const double limit_s = 600;
  for (double t = 0; t < limit_s; t += sc.period_s) {
    d.advance();
    const control::ServoStatus& s = d.controller().status().servo;
    if (s.state == State::Idle && s.all_homed) return true;
    if (s.state == State::Faulted || s.state == State::EStopped) break;
  }
  fmt::print(stderr, "error: homing did not finish: {}\n", d.controller().status().fault_text);
  return false;
}

/// Follows the run until it ends; continues program stops and manual tool changes at once. A stop
/// asked through `stop` holds the feed on the path, then aborts once the machine is at rest.
void follow(Driver& d, const SessionHooks& hooks, const std::atomic<int>* stop, SessionEnd& end) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::uint64_t finished_before = d.controller().status().runs_finished;
  control::TraceSample sample;
  std::uint64_t n = 0;
  bool nudged = false, held = false, aborted = false;
  for (;;) {
    d.advance();
    while (d.channels().trace.try_pop(sample)) {
      if (sample.activity == control::Activity::Program && hooks.sample) hooks.sample(sample);
    }
    const control::ControllerStatus st = d.controller().status();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (hooks.progress && (++n % 256 == 0)) hooks.progress(st, wall);
    print_notes(d.controller());
    const bool waiting = st.servo.state == State::Stopped || st.servo.wait == control::Wait::ManualToolChange;
    if (stop != nullptr && stop->load(std::memory_order_relaxed) != 0 && !aborted) {
      end.stopped_by = stop->load(std::memory_order_relaxed);
      if (!held)
        d.controller().submit(Request::simple(CommandKind::FeedHold));
      else if (st.servo.path_velocity == 0)
        d.controller().submit(Request::simple(CommandKind::Abort));
      aborted = held && st.servo.path_velocity == 0;
      held = true;
    }
    if (waiting && !nudged && end.stopped_by == 0) {
      d.controller().submit(Request::simple(st.servo.state == State::Stopped ? CommandKind::CycleStart
                                                                             : CommandKind::ToolChanged));
    }
    nudged = waiting;
    if (st.run_active) continue;
    end.wall_s = wall;
    end.finished = st.runs_finished > finished_before;
    if (!end.finished) {
      // (a fault was printed as its note already)
      if (!st.fault_text.empty())
        end.fault = st.fault_text;
      else if (end.stopped_by != 0)
        end.fault =
            fmt::format("stopped by {} (feed hold on the path, then abort)", signal_name(end.stopped_by));
      else
        end.fault = fmt::format("the run ended in state {}", control::to_string(st.servo.state));
      if (st.fault_text.empty()) fmt::print(stderr, "error: {}\n", end.fault);
      end.limit_touched = st.servo.fault.kind == control::FaultKind::SoftLimit ||
                          st.servo.fault.kind == control::FaultKind::LimitSwitch;
    }
    if (hooks.progress) hooks.progress(st, wall);
    return;
  }
}

}  // namespace

SessionEnd run_session(const SessionOptions& o, const SessionHooks& hooks) {
  SessionEnd end;
  end.exit_code = kExitProgram;
  const config::ProfileLoad load = config::load_profile(o.machine, o.sets);
  print(load.diagnostics);
  if (!load.ok()) {
    const bool unreadable =
        !load.diagnostics.items().empty() && load.diagnostics.items()[0].code == "config.file";
    end.exit_code = unreadable ? kExitUsage : kExitProgram;
    return end;
  }
  end.profile = *load.profile;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(o.file, ec)) {
    fmt::print(stderr, "error: cannot read the program {}\n", o.file);
    end.exit_code = kExitUsage;
    return end;
  }
  Diagnostics diags;
  auto source = control::GcodeProgramSource::create(end.profile, diags);
  print(diags);
  if (!source) return end;

  std::unique_ptr<Driver> driver;
  if (o.realtime) {
    auto rt = std::make_unique<RealtimeDriver>(end.profile, source);
    if (!rt->start()) {
      fmt::print(stderr, "error: cannot start the servo thread\n");
      return end;
    }
    driver = std::move(rt);
  } else {
    driver = std::make_unique<VirtualDriver>(end.profile, source);
  }
  Driver& d = *driver;
  const control::ServoConfig& sc = d.controller().servo_config();
  if (!must(d, Request::simple(CommandKind::MachineOn)) || !home_if_needed(d, sc) ||
      !must(d, Request::set_mode(control::Mode::Auto)) || !must(d, Request::open(o.file))) {
    return end;
  }
  end.program = d.controller().open_program();
  if (hooks.opened) hooks.opened(end.profile, *end.program);
  d.channels().trace_enabled = true;
  if (!must(d, Request::simple(CommandKind::CycleStart))) return end;
  follow(d, hooks, o.stop, end);
  end.exit_code = end.finished ? kExitOk : end.stopped_by != 0 ? 128 + end.stopped_by : kExitProgram;
  return end;
}

}  // namespace opencnc::cli
