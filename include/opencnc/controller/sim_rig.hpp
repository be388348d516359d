// SPDX-License-Identifier: GPL-3.0-or-later
// SimRig — the whole controller on the simulated machine, driven in virtual time: the servo
// ticks, and the controller's non-real-time work runs at fixed points between ticks, so that a
// run repeats bit for bit. Used by the scenario tests, the benchmarks and `opencnc run`.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/channels.hpp"
#include "opencnc/control/servo.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/machine_setup.hpp"
#include "opencnc/machine/sim_machine.hpp"

namespace opencnc::controller {

/// Owns the simulated machine, the channels, the servo and the controller. One thread.
class SimRig {
 public:
  /// `service_every`: the controller's work runs before every n-th tick (1 = every tick).
  /// `options`: the controller's; with long work on a thread, virtual time goes on while a program
  /// is checked (paced virtual time for a server), and runs no longer repeat bit for bit.
  explicit SimRig(const config::MachineProfile& profile, std::shared_ptr<ProgramSource> source = nullptr,
                  int service_every = 1, ControllerOptions options = {});
  /// The machine as its features set it up: `setup`'s program source, and its features,
  /// observers, texts and move reaches installed on the controller.
  SimRig(const config::MachineProfile& profile, MachineSetup& setup, int service_every = 1,
         ControllerOptions options = {});
  ~SimRig();

  /// One servo period (with the controller's work first when it is due).
  void step();
  /// `n` periods.
  void run(std::uint64_t n);
  /// Periods until `done()` holds (checked after each) or `max_ticks`; returns whether it held.
  bool run_until(const std::function<bool()>& done, std::uint64_t max_ticks);
  /// Submits `r` and runs until its outcome is known (at most `max_ticks`).
  Outcome request(Request r, std::uint64_t max_ticks = 1000);

  Controller& controller() noexcept { return *controller_; }
  machine::SimMachine& machine() noexcept { return *machine_; }
  control::Servo& servo() noexcept { return *servo_; }
  control::ServoChannels& channels() noexcept { return *channels_; }
  /// The controller's status (as of its last service).
  ControllerStatus status() const { return controller_->status(); }
  std::uint64_t ticks() const noexcept { return ticks_; }

 private:
  std::unique_ptr<control::ServoChannels> channels_;
  std::unique_ptr<machine::SimMachine> machine_;
  std::unique_ptr<control::Servo> servo_;
  std::unique_ptr<Controller> controller_;
  int service_every_;
  std::uint64_t ticks_ = 0;
};

}  // namespace opencnc::controller
