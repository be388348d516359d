// SPDX-License-Identifier: GPL-3.0-or-later
// The heartbeat watch and the guard that makes a silent controller a controlled stop.
#include "opencnc/control/heartbeat.hpp"

namespace opencnc::control {

bool HeartbeatWatch::update() noexcept {
  const std::uint64_t now = beat_->load(std::memory_order_acquire);
  if (now != last_) {
    last_ = now;
    quiet_ticks_ = 0;
    alive_ = true;
    return true;
  }
  if (quiet_ticks_ < timeout_ticks_) ++quiet_ticks_;
  if (alive_ && quiet_ticks_ >= timeout_ticks_) {
    alive_ = false;
    ++losses_;
  }
  return alive_;
}

void HeartbeatGuard::refresh_capabilities() noexcept {
  inner_power_monitor_ = inner_->capabilities().power_monitor;
}

machine::MachineCapabilities HeartbeatGuard::capabilities() const noexcept {
  machine::MachineCapabilities c = inner_->capabilities();
  c.power_monitor = true;
  return c;
}

void HeartbeatGuard::read(machine::MachineInputs& in) noexcept {
  inner_->read(in);
  if (!inner_power_monitor_) in.power = machine::PowerInputs{};
  if (!watch_->alive()) in.power.mains_ok = false;
}

void HeartbeatGuard::write(const machine::MachineOutputs& out) noexcept {
  bool enabled = false;
  for (const machine::JointOutputs& j : out.joints) enabled = enabled || j.enable;
  drives_enabled_ = enabled;
  inner_->write(out);
}

}  // namespace opencnc::control
