// SPDX-License-Identifier: GPL-3.0-or-later
// SimRig: controller + servo + simulated machine in virtual time.
#include "opencnc/controller/sim_rig.hpp"

#include "opencnc/controller/servo_setup.hpp"

namespace opencnc::controller {

SimRig::SimRig(const config::MachineProfile& profile, std::shared_ptr<ProgramSource> source,
               int service_every, ControllerOptions options)
    : channels_(std::make_unique<control::ServoChannels>()),
      machine_(std::make_unique<machine::SimMachine>(config::sim_machine_config(profile))),
      servo_(std::make_unique<control::Servo>(servo_config(profile), *channels_, *machine_)),
      controller_(std::make_unique<Controller>(profile, *channels_, std::move(source), options)),
      service_every_(service_every < 1 ? 1 : service_every) {}

SimRig::SimRig(const config::MachineProfile& profile, MachineSetup& setup, int service_every,
               ControllerOptions options)
    : SimRig(profile, setup.source(), service_every, options) {
  setup.install(*controller_);
}

SimRig::~SimRig() = default;

void SimRig::step() {
  if (ticks_ % static_cast<std::uint64_t>(service_every_) == 0) controller_->service();
  servo_->tick();
  ++ticks_;
}

void SimRig::run(std::uint64_t n) {
  for (std::uint64_t i = 0; i < n; ++i) step();
}

bool SimRig::run_until(const std::function<bool()>& done, std::uint64_t max_ticks) {
  for (std::uint64_t i = 0; i < max_ticks; ++i) {
    step();
    if (done()) return true;
  }
  return false;
}

Outcome SimRig::request(Request r, std::uint64_t max_ticks) {
  const std::uint64_t id = controller_->submit(std::move(r));
  std::optional<Outcome> o;
  for (std::uint64_t i = 0; i < max_ticks && !(o = controller_->outcome(id)); ++i) step();
  if (!o) {  // the answer of the last tick is read by the next service
    controller_->service();
    o = controller_->outcome(id);
  }
  return o ? *o : Outcome{false, control::Refusal::Busy, "no answer", {}};
}

}  // namespace opencnc::controller
