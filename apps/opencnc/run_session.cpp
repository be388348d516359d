// SPDX-License-Identifier: GPL-3.0-or-later
// One program run for the command line, in virtual time (SimRig) or with a real-time servo thread.
#include "run_session.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "commands.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/control/clock.hpp"
#include "opencnc/control/servo.hpp"
#include "opencnc/control/triple_buffer.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/hal_link.hpp"
#include "opencnc/controller/machine_setup.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/features/features.hpp"
#include "stop_signals.hpp"

namespace opencnc::cli {

namespace {

using control::CommandKind;
using control::State;
using controller::ControllerEvent;
using controller::ControllerEventKind;
using controller::Request;

void print_one(const Diagnostic& d) {
  fmt::print(stderr, "{}{}\n", d.format(), d.code.empty() ? "" : fmt::format(" [{}]", d.code));
}

void print(const Diagnostics& diags) {
  for (const Diagnostic& d : diags.items()) print_one(d);
}

/// The features' set-up problems: one with a setting the command line gave (`setting.NAME`) names
/// its option (`--NAME FILE: why`), as the option's own checks do.
void print_setup(const Diagnostics& diags) {
  for (const Diagnostic& d : diags.items()) {
    if (d.code.rfind("setting.", 0) == 0)
      fmt::print(stderr, "error: --{} {}: {}\n", d.code.substr(8), d.file, d.message);
    else
      print_one(d);
  }
}

/// Moves the controller and the servo on: one servo period in virtual time, or one period of
/// the controller's loop while the real-time thread ticks on its own.
class Driver {
 public:
  virtual ~Driver() = default;
  virtual void advance() = 0;
  virtual controller::Controller& controller() = 0;
  /// Whether time goes on by itself (a real-time servo) while the session waits for the operator.
  virtual bool ticks_by_itself() const = 0;
  /// The simulated operator's hand moves hand-fed joint `joint` toward `target` at `speed`.
  virtual void set_hand_target(int joint, double target, double speed) = 0;
  /// The simulated mains fail (virtual time only: cmd_run refuses --inject with --realtime or --hal).
  virtual void cut_mains() = 0;
  /// A simulated analog input goes to `value` over `ramp_s` (0: at once). Virtual time only.
  virtual void drive_analog(int /*channel*/, double /*value*/, double /*ramp_s*/) {}
  /// The simulated machine (virtual time only; null elsewhere): the features' injected faults.
  virtual machine::SimMachine* sim_machine() { return nullptr; }
};

class VirtualDriver final : public Driver {
 public:
  VirtualDriver(const config::MachineProfile& p, std::shared_ptr<controller::ProgramSource> s)
      : rig_(p, std::move(s)) {}
  void advance() override { rig_.step(); }
  controller::Controller& controller() override { return rig_.controller(); }
  bool ticks_by_itself() const override { return false; }
  void set_hand_target(int joint, double target, double speed) override {
    rig_.machine().set_hand_target(joint, target, speed);
  }
  void cut_mains() override { rig_.machine().set_mains_ok(false); }
  machine::SimMachine* sim_machine() override { return &rig_.machine(); }
  void drive_analog(int channel, double value, double ramp_s) override {
    machine::SimMachine& m = rig_.machine();
    if (ramp_s > 0) {
      m.drift_analog_input(channel, value, (value - m.analog_input(channel)) / ramp_s);
    } else {
      m.set_analog_input(channel, value);
    }
  }

 private:
  controller::SimRig rig_;
};

/// The simulated machine behind a real-time servo: the servo thread alone touches it, so the
/// hand's targets from the controller's thread are handed over (wait-free) and applied there.
class HandedSimMachine final : public machine::MachineIO {
 public:
  struct HandTarget {
    int joint = -1;
    double target = 0, speed = 0;
  };
  explicit HandedSimMachine(const machine::SimMachineConfig& c) : sim_(c) {}
  machine::MachineCapabilities capabilities() const noexcept override { return sim_.capabilities(); }
  void read(machine::MachineInputs& in) noexcept override { sim_.read(in); }
  void write(const machine::MachineOutputs& out) noexcept override {
    if (hand_.update()) sim_.set_hand_target(hand_.front().joint, hand_.front().target, hand_.front().speed);
    sim_.write(out);
  }
  /// Controller thread.
  void set_hand_target(int joint, double target, double speed) noexcept {
    hand_.write({joint, target, speed});
  }

 private:
  machine::SimMachine sim_;
  control::TripleBuffer<HandTarget> hand_;
};

/// A tick that runs by itself (a real-time thread, HAL) is never kept waiting by the controller:
/// its long work (preflights) runs on a thread of its own.
constexpr controller::ControllerOptions kTickByItself{.long_work_on_thread = true};

class RealtimeDriver final : public Driver {
 public:
  RealtimeDriver(const config::MachineProfile& p, std::shared_ptr<controller::ProgramSource> s)
      : channels_(std::make_unique<control::ServoChannels>()),
        sim_(std::make_unique<HandedSimMachine>(config::sim_machine_config(p))),
        servo_(std::make_unique<control::Servo>(controller::servo_config(p), *channels_, *sim_)),
        controller_(std::make_unique<controller::Controller>(p, *channels_, std::move(s), kTickByItself)),
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
  controller::Controller& controller() override { return *controller_; }
  bool ticks_by_itself() const override { return true; }
  void set_hand_target(int joint, double target, double speed) override {
    sim_->set_hand_target(joint, target, speed);
  }
  void cut_mains() override {}  // the servo thread alone touches the machine; refused before

 private:
  std::unique_ptr<control::ServoChannels> channels_;
  std::unique_ptr<HandedSimMachine> sim_;
  std::unique_ptr<control::Servo> servo_;
  std::unique_ptr<controller::Controller> controller_;
  std::chrono::duration<double> period_;
  control::RealtimeClock clock_;
};

/// The tick runs in LinuxCNC's HAL (opencnc_rt.so); this process is the controller only, linked
/// to it through shared memory (controller::HalLink: set-up, heartbeat).
class HalDriver final : public Driver {
 public:
  HalDriver(const config::MachineProfile& p, std::shared_ptr<controller::ProgramSource> s,
            std::unique_ptr<controller::HalLink> link)
      : link_(std::move(link)),
        controller_(
            std::make_unique<controller::Controller>(p, link_->channels(), std::move(s), kTickByItself)),
        period_(std::chrono::duration<double>(p.servo_period_s)) {}
  ~HalDriver() override { controller_.reset(); }  // before the link: it unmaps the channels
  void advance() override {
    controller_->service();
    std::this_thread::sleep_for(period_);
  }
  controller::Controller& controller() override { return *controller_; }
  bool ticks_by_itself() const override { return true; }
  void set_hand_target(int, double, double) override {}  // a real hand moves a real axis
  void cut_mains() override {}  // real mains: nothing to simulate (cmd_run refuses --inject with --hal)

 private:
  std::unique_ptr<controller::HalLink> link_;
  std::unique_ptr<controller::Controller> controller_;
  std::chrono::duration<double> period_;
};

/// Submits `r` and advances until it is answered.
controller::Outcome ask(Driver& d, Request r) {
  const std::uint64_t id = d.controller().submit(std::move(r));
  for (int i = 0; i < 100000; ++i) {
    d.advance();
    if (auto o = d.controller().outcome(id)) return *o;
  }
  return {false, control::Refusal::Busy, "the controller does not answer", {}};
}

bool must(Driver& d, Request r) {
  const std::string name = r.name();
  const controller::Outcome o = ask(d, std::move(r));
  print(o.diagnostics);
  if (!o.accepted) fmt::print(stderr, "error: {}: {}\n", name, o.message);
  return o.accepted;
}

bool home_if_needed(Driver& d, const control::ServoConfig& sc) {
  if (!sc.homing_required) return true;
  if (!must(d, Request::set_mode(control::Mode::Manual)) || !must(d, Request::home())) return false;
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

/// Lines typed by the operator on stdin (a terminal or a pipe), read without blocking the run.
class OperatorInput {
 public:
  /// The next whole line, waiting at most `timeout_ms` (−1: as long as it takes); nothing when
  /// none came in time or stdin is closed (closed() tells).
  std::optional<std::string> line(int timeout_ms) {
    for (;;) {
      if (const auto nl = buffer_.find('\n'); nl != std::string::npos) {
        std::string l = buffer_.substr(0, nl);
        buffer_.erase(0, nl + 1);
        return l;
      }
      if (closed_) return std::nullopt;
      pollfd p{STDIN_FILENO, POLLIN, 0};
      const int n = ::poll(&p, 1, timeout_ms);
      if (n < 0 && errno == EINTR) return std::nullopt;  // (a signal: the caller looks at its stop flag)
      if (n <= 0) return std::nullopt;
      char chunk[256];
      const ssize_t got = ::read(STDIN_FILENO, chunk, sizeof chunk);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) {
        closed_ = true;
        if (!buffer_.empty()) {  // a last line without its newline
          std::string l = std::move(buffer_);
          buffer_.clear();
          return l;
        }
        return std::nullopt;
      }
      buffer_.append(chunk, static_cast<std::size_t>(got));
    }
  }
  bool closed() const noexcept { return closed_; }

 private:
  std::string buffer_;
  bool closed_ = false;
};

/// What the run waits for the operator for, if anything: the question and the request that
/// answers "go on".
struct OperatorWait {
  std::string question;
  Request go_on = Request::simple(CommandKind::CycleStart);
};

std::optional<OperatorWait> operator_wait(const controller::ControllerStatus& st) {
  if (st.servo.state == State::Stopped)
    return OperatorWait{st.wait_text, Request::simple(CommandKind::CycleStart)};
  if (st.servo.wait == control::Wait::ManualToolChange)
    return OperatorWait{st.wait_text, Request::simple(CommandKind::ToolChanged)};
  return std::nullopt;
}

void print_event(const ControllerEvent& e) {
  if (e.kind != ControllerEventKind::Note) return;
  if (e.severity == Severity::Note) {
    fmt::print(stderr, "message: {}\n", e.text);
  } else {
    fmt::print(stderr, "{}: {}{}\n", e.severity == Severity::Warning ? "warning" : "error", e.text,
               e.code.empty() ? "" : fmt::format(" [{}]", e.code));
  }
}

/// The simulated machine's hand brings a hand-fed axis where the program waits for it (retracts
/// quickly, feeds down at 2 mm/s): on the command line there is no hand wheel to turn.
void bring_hand_axis(Driver& d, const control::ServoStatus& s) {
  if (s.wait != control::Wait::HandAxis || s.hand_wait.axis < 0) return;
  for (int j = 0; j < s.joint_count; ++j) {
    if (d.controller().servo_config().joints[static_cast<std::size_t>(j)].axis == s.hand_wait.axis)
      d.set_hand_target(j, s.hand_wait.target, s.hand_wait.retract ? 40.0 : 2.0);
  }
}

/// A stop asked through SessionOptions::stop (SIGINT, SIGTERM) or by SessionOptions::max_time_s:
/// feed hold on the path, then abort once the machine is at rest. Where a hold does not act (a
/// thread or tap follows the spindle: G33, G76, G33.1) the abort comes at once, as it does at a
/// second signal: it brakes on the path too, the run ends and the report is written. Call every
/// period; records why in `end`.
class StopOnThePath {
 public:
  StopOnThePath(const SessionOptions& o) : flag_(o.stop), count_(o.stops), max_time_s_(o.max_time_s) {}
  bool requested() const noexcept { return signal() != 0 || over_time_; }
  void step(Driver& d, const controller::ControllerStatus& st, SessionEnd& end) {
    if (run_start_s_ < 0) run_start_s_ = st.servo.time_s;
    if (max_time_s_ > 0 && !over_time_ && signal() == 0 && st.servo.time_s - run_start_s_ > max_time_s_) {
      over_time_ = end.over_max_time = true;
      fmt::print(stderr, "error: the run passed --max-time {:g} s: stopping on the path\n", max_time_s_);
    }
    if (!requested() || aborted_) return;
    if (signal() != 0) end.stopped_by = signal();
    const bool again = count_ != nullptr && count_->load(std::memory_order_relaxed) >= 2;
    const bool hold_does_not_act = held_ && st.servo.spindle_synced;
    if (!held_ && !again) {
      d.controller().submit(Request::simple(CommandKind::FeedHold));
      held_ = true;
      return;
    }
    if (again || hold_does_not_act || st.servo.path_velocity == 0) {
      d.controller().submit(Request::simple(CommandKind::Abort));
      aborted_ = true;
    }
  }

 private:
  int signal() const noexcept { return flag_ != nullptr ? flag_->load(std::memory_order_relaxed) : 0; }
  const std::atomic<int>* flag_;
  const std::atomic<int>* count_;
  double max_time_s_ = 0;
  double run_start_s_ = -1;
  bool held_ = false, aborted_ = false, over_time_ = false;
};

/// The operator at the terminal for a feature that holds the program and asks (SessionOperator).
class TerminalOperator final : public SessionOperator {
 public:
  TerminalOperator(Driver& d, const SessionOptions& o, OperatorInput& input) : d_(d), o_(o), input_(input) {}
  std::optional<std::string> ask(const std::string& question) override {
    if (o_.unattended || input_.closed()) return std::nullopt;
    fmt::print(stderr, "\n{}\n", question);
    std::optional<std::string> answer;
    while (!answer && !input_.closed()) {
      answer = input_.line(d_.ticks_by_itself() ? 10 : -1);
      if (!answer && d_.ticks_by_itself()) d_.advance();
    }
    return answer;
  }
  bool must(Request r) override { return cli::must(d_, std::move(r)); }
  void submit(Request r) override { d_.controller().submit(std::move(r)); }

 private:
  Driver& d_;
  const SessionOptions& o_;
  OperatorInput& input_;
};

/// Follows the job started by cycle start until it ends, with the operator where it waits (and
/// the machine's hand at the hand-fed axes); a feature that holds the program asks the operator
/// through SessionHooks::on_event.
void follow(Driver& d, controller::EventCursor& cursor, const SessionOptions& o, const SessionHooks& hooks,
            SessionEnd& end) {
  StopOnThePath stop(o);
  const auto t0 = std::chrono::steady_clock::now();
  OperatorInput input;
  std::uint32_t job = 0;
  std::uint64_t asked_tick = ~std::uint64_t{0};  // the wait already answered (by its start tick)
  std::uint64_t n = 0;
  TerminalOperator op(d, o, input);
  bool mains_cut = false, analog_driven = false, alarm_abort = false;
  for (;;) {
    d.advance();
    std::optional<ControllerEvent> ended;
    for (const ControllerEvent& e : cursor.next()) {
      print_event(e);
      if (e.kind == ControllerEventKind::JobStarted && job == 0 && e.job == controller::JobKind::Program)
        job = e.job_id;
      if (e.kind == ControllerEventKind::JobEnded && e.job_id == job) ended = e;
      if (hooks.on_event) hooks.on_event(e, op);  // a feature that holds the program asks the operator
    }
    const controller::ControllerStatus st = d.controller().status();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.mains_off_s >= 0 && !mains_cut && st.servo.time_s >= o.mains_off_s) {
      d.cut_mains();  // the servo sees it at its next period
      mains_cut = true;
    }
    if (o.analog && !analog_driven && st.servo.time_s >= o.analog->at_s) {
      d.drive_analog(o.analog->channel, o.analog->value, o.analog->ramp_s);
      analog_driven = true;
    }
    // A feed-hold alarm on an injected input that stays out of range: in virtual time nothing
    // brings it back, so the run is aborted where it stands (its note says why).
    if (o.analog && analog_driven && !alarm_abort && st.servo.state == State::Held &&
        st.servo.alarms_active != 0 && st.servo.path_velocity == 0 &&
        st.servo.time_s >= o.analog->at_s + o.analog->ramp_s && !stop.requested()) {
      alarm_abort = true;
      fmt::print(
          stderr,
          "error: a process alarm holds the program and the injected input stays out of range: abort\n");
      d.controller().submit(Request::simple(CommandKind::Abort));
    }
    if (hooks.progress && (++n % 256 == 0)) hooks.progress(st, wall);
    bring_hand_axis(d, st.servo);
    if (hooks.tick) hooks.tick(d.controller(), st, d.sim_machine());
    if (ended && hooks.goes_on && hooks.goes_on(*ended)) {
      job = 0;  // the job that resumes the program is followed next
      ended.reset();
    }
    if (ended) {
      end.wall_s = wall;
      end.finished = ended->end == controller::JobEnd::Finished;
      if (!end.finished) {
        // (a fault was printed as its note already)
        if (!st.fault_text.empty())
          end.fault = st.fault_text;
        else if (end.stopped_by != 0)
          end.fault =
              fmt::format("stopped by {} (feed hold on the path, then abort)", signal_name(end.stopped_by));
        else if (end.over_max_time)
          end.fault =
              fmt::format("stopped by --max-time {:g} s (feed hold on the path, then abort)", o.max_time_s);
        else
          end.fault = fmt::format("the program ended: {}", controller::to_string(ended->end));
        if (st.fault_text.empty()) fmt::print(stderr, "error: {}\n", end.fault);
        end.limit_touched = st.servo.fault.kind == control::FaultKind::SoftLimit ||
                            st.servo.fault.kind == control::FaultKind::LimitSwitch;
      }
      if (hooks.progress) hooks.progress(st, wall);
      return;
    }
    stop.step(d, st, end);
    const std::optional<OperatorWait> wait = stop.requested() ? std::nullopt : operator_wait(st);
    if (!wait) {
      asked_tick = ~std::uint64_t{0};
      continue;
    }
    if (asked_tick != ~std::uint64_t{0}) continue;  // answered: waiting for the machine to go on
    asked_tick = st.servo.tick;
    if (o.unattended) {
      d.controller().submit(wait->go_on);
      continue;
    }
    fmt::print(stderr, "\nwaiting for {}: press Enter to continue, or a and Enter to abort\n",
               wait->question);
    std::optional<std::string> answer;
    while (!answer && !input.closed() && !stop.requested()) {
      answer = input.line(d.ticks_by_itself() ? 10 : -1);
      if (!answer && d.ticks_by_itself()) d.advance();
    }
    if (stop.requested()) continue;  // stopped at the question: the stop aborts it
    if (!answer) {
      fmt::print(stderr,
                 "error: the program waits for {} and no one can answer (stdin is closed): run it with "
                 "--unattended to let it go on by itself\n",
                 wait->question);
      d.controller().submit(Request::simple(CommandKind::Abort));
    } else if (*answer == "a" || *answer == "A") {
      d.controller().submit(Request::simple(CommandKind::Abort));
    } else {
      d.controller().submit(wait->go_on);
    }
  }
}

/// What the preflight could only check with assumed answers (a probe's trip, an input's value).
void note_assumptions(const controller::PreflightSummary& s) {
  if (s.assumed_moves == 0) return;
  std::string lines;
  for (const controller::SourceLocation& l : s.assumed_lines) {
    if (lines.size() > 200) {
      lines += ", …";
      break;
    }
    lines += (lines.empty() ? "" : ", ") + controller::to_string(l);
  }
  const auto plural = [](std::uint64_t n, const char* one, const char* many) {
    return fmt::format("{} {}", n, n == 1 ? one : many);
  };
  fmt::print(
      stderr,
      "note: {} {} on what the machine answers while the program runs ({}); checked with assumed answers, "
      "they are checked again with the real ones before they run: {}\n",
      plural(s.assumed_moves, "move", "moves"), s.assumed_moves == 1 ? "rests" : "rest",
      plural(s.sync_points, "sync point", "sync points"), lines);
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
  if (const std::string why = unreadable_input(o.file, SIZE_MAX); !why.empty()) {
    fmt::print(stderr, "error: cannot read the program {}: {}\n", o.file, why);
    end.exit_code = kExitUsage;
    return end;
  }
  // The machine as its features set it up (features::set_up), as every front end does.
  Diagnostics diags;
  controller::MachineSetup::Options asked;
  asked.reports = o.reports;
  asked.settings = o.settings;
  if (o.tool_table_in_memory) asked.settings["tool-table"] = "memory";
  std::unique_ptr<controller::MachineSetup> setup =
      controller::MachineSetup::create(end.profile, asked, diags);
  print(diags);
  if (!setup) return end;
  const bool set_up = features::set_up(*setup);
  print_setup(setup->diagnostics());
  if (!set_up) {  // a setting the command line gave is a usage error; the profile's, the program's
    const auto& items = setup->diagnostics().items();
    if (std::any_of(items.begin(), items.end(),
                    [](const Diagnostic& d) { return d.code.rfind("setting.", 0) == 0; }))
      end.exit_code = kExitUsage;
    return end;
  }
  if (hooks.set_up && !hooks.set_up(*setup)) {
    end.exit_code = kExitUsage;
    return end;
  }
  const std::shared_ptr<controller::ProgramSource> source = setup->source();

  std::unique_ptr<Driver> driver;
  if (o.hal) {
    std::string error;
    auto link = controller::HalLink::attach(o.hal_shm, end.profile, error);
    if (!link) {
      fmt::print(stderr, "error: --hal: {}\n", error);
      end.exit_code = kExitUsage;
      return end;
    }
    driver = std::make_unique<HalDriver>(end.profile, source, std::move(link));
    // A previous controller's exit (its heartbeat stopped) left the tick faulted: clear it.
    // (Refused when there is nothing to reset: that is fine.)
    ask(*driver, Request::simple(CommandKind::Reset));
  } else if (o.realtime) {
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
  setup->install(d.controller());
  const control::ServoConfig& sc = d.controller().servo_config();
  // Through HAL the machine may already be on: a previous controller left it idle.
  const bool on = o.hal && d.controller().status().servo.state == State::Idle;
  if (!(on || must(d, Request::simple(CommandKind::MachineOn))) || !home_if_needed(d, sc) ||
      !must(d, Request::set_mode(control::Mode::Auto)) || !must(d, Request::open(o.file))) {
    return end;
  }
  end.program = d.controller().open_program();
  note_assumptions(end.program->preflight.summary);
  if (hooks.may_start && !hooks.may_start(end.profile, *end.program)) return end;
  if (hooks.opened) {
    for (auto& [observer, options] : hooks.opened(end.profile, *end.program))
      d.controller().attach(observer, options);
  }
  controller::EventCursor cursor(d.controller().events());
  if (!must(d, Request::simple(CommandKind::CycleStart))) return end;
  follow(d, cursor, o, hooks, end);
  if (hooks.finished) hooks.finished(d.sim_machine());
  end.exit_code = end.finished ? kExitOk : end.stopped_by != 0 ? 128 + end.stopped_by : kExitProgram;
  return end;
}

}  // namespace opencnc::cli
