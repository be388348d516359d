// SPDX-License-Identifier: GPL-3.0-or-later
// The servo alone on the simulated machine, talked to through its channels as the controller
// would: commands in, events and status out, blocks from a planner pumped between ticks.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <vector>

#include "opencnc/canon/program.hpp"
#include "opencnc/canon/program_tail.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/machine_action.hpp"
#include "opencnc/control/servo.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/machine/sim_machine.hpp"
#include "opencnc/plan/planner.hpp"

namespace opencnc::control::test {

class ServoHarness {
 public:
  explicit ServoHarness(const config::MachineProfile& profile)
      : profile_(profile),
        channels_(std::make_unique<ServoChannels>()),
        sim_(std::make_unique<machine::SimMachine>(config::sim_machine_config(profile))),
        servo_(std::make_unique<Servo>(controller::servo_config(profile), *channels_, *sim_)) {
    tick();
  }

  /// `n` periods, pumping the planner and the program's machine actions before each.
  void tick(int n = 1) {
    for (int i = 0; i < n; ++i) {
      pump();
      servo_->tick();
      drain();
    }
  }

  /// Sends `c` and runs one period; the servo's answer (None = accepted).
  Refusal send(Command c) {
    c.id = next_id_++;
    EXPECT_TRUE(channels_->commands.try_push(c));
    tick();
    for (const ServoEvent& e : events_) {
      if ((e.kind == EventKind::Accepted || e.kind == EventKind::Refused) && e.command_id == c.id)
        return e.refusal;
    }
    ADD_FAILURE() << "no answer to " << to_string(c.kind);
    return Refusal::BadValue;
  }
  Refusal send(CommandKind k) {
    Command c;
    c.kind = k;
    return send(c);
  }
  Refusal send_mode(Mode m) {
    Command c;
    c.kind = CommandKind::SetMode;
    c.mode = m;
    return send(c);
  }
  Refusal jog(Axis a, double velocity) {
    Command c;
    c.kind = CommandKind::JogContinuous;
    c.axis = static_cast<std::int8_t>(index(a));
    c.value = velocity;
    return send(c);
  }
  Refusal home(int axis = -1) {
    Command c;
    c.kind = CommandKind::Home;
    c.axis = static_cast<std::int8_t>(axis);
    return send(c);
  }

  /// Plans `program` (started where the machine stands) and asks the servo to run it.
  Refusal run(const canon::Program& program, Mode mode) {
    program_ = canon::program_tail(program, 0, status().commanded);
    planner_ = std::make_unique<plan::Planner>(controller::machine_limits(profile_),
                                               controller::planner_config(profile_));
    EXPECT_TRUE(planner_->start(*program_));
    next_action_ = 0;
    Command c;
    c.kind = CommandKind::StartRun;
    c.run_mode = mode;
    c.run_id = ++run_id_;
    c.first_block = channels_->blocks.pushed();
    c.first_action = channels_->actions.pushed();
    pump();
    return send(c);
  }
  void stop_planning() { planner_.reset(); }

  /// Periods until `done` or `max`; whether it held.
  template <typename F>
  bool until(F done, int max) {
    for (int i = 0; i < max; ++i) {
      if (done()) return true;
      tick();
    }
    return done();
  }

  const ServoStatus& status() {
    channels_->status.update();
    return channels_->status.front();
  }
  State state() { return status().state; }
  machine::SimMachine& sim() { return *sim_; }
  ServoChannels& channels() { return *channels_; }
  Servo& servo() { return *servo_; }
  const std::vector<ServoEvent>& events() const { return events_; }
  /// The last event of `kind`, if any.
  std::optional<ServoEvent> last(EventKind kind) const {
    for (auto it = events_.rbegin(); it != events_.rend(); ++it) {
      if (it->kind == kind) return *it;
    }
    return std::nullopt;
  }

 private:
  void pump() {
    if (!planner_) return;
    while (next_action_ < program_->action_count()) {
      const auto a = machine_action(*program_, next_action_);
      if (a && !channels_->actions.try_push(*a)) break;
      ++next_action_;
    }
    if (planner_->pump(channels_->blocks) != plan::PlanStatus::Working) planner_.reset();
  }
  void drain() {
    ServoEvent e;
    while (channels_->events.try_pop(e)) events_.push_back(e);
  }

  config::MachineProfile profile_;
  std::unique_ptr<ServoChannels> channels_;
  std::unique_ptr<machine::SimMachine> sim_;
  std::unique_ptr<Servo> servo_;
  std::shared_ptr<canon::Program> program_;
  std::unique_ptr<plan::Planner> planner_;
  std::uint32_t next_action_ = 0;
  std::uint64_t next_id_ = 1;
  std::uint32_t run_id_ = 0;
  std::vector<ServoEvent> events_;
};

}  // namespace opencnc::control::test
