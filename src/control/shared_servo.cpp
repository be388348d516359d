// SPDX-License-Identifier: GPL-3.0-or-later
// The servo tick hosted over shared memory: set-up hand-over, heartbeat, safe outputs.
#include "opencnc/control/shared_servo.hpp"

#include <cstring>

namespace opencnc::control {

SharedServoHost::SharedServoHost(SharedSegment& segment, ConfigurableMachine& machine) noexcept
    : segment_(&segment),
      machine_(&machine),
      watch_(segment.header.heartbeat,
             segment.header.heartbeat_timeout_ticks.load(std::memory_order_relaxed)),
      guard_(machine, watch_) {}

SharedServoHost::~SharedServoHost() {
  if (servo_ != nullptr) servo_->~Servo();
}

bool SharedServoHost::tick() noexcept {
  SharedHeader& h = segment_->header;
  const bool was_alive = watch_.alive();
  const bool alive = watch_.update();
  h.controller_alive.store(alive, std::memory_order_relaxed);
  if (was_alive && !alive) h.heartbeat_losses.fetch_add(1, std::memory_order_relaxed);
  take_setup();
  if (servo_ != nullptr) {
    servo_->tick();
  } else {
    machine::MachineInputs in;
    guard_.read(in);
    guard_.write(machine::MachineOutputs{});  // drives disabled, e-stop chain open
  }
  h.ticks.fetch_add(1, std::memory_order_release);
  return true;
}

// A new set-up replaces the servo only while no drive is enabled (a moving machine keeps the servo
// that moves it; the controller sees the set-up pending). An identical set-up keeps the servo and
// its state (homed joints survive a restart of the controller), but not what the previous
// controller staged and did not apply: the new one fills the pitch buffers the tick does not read.
void SharedServoHost::take_setup() noexcept {
  SharedHeader& h = segment_->header;
  const std::uint64_t generation = h.setup_generation.load(std::memory_order_acquire);
  if (generation == h.setup_taken.load(std::memory_order_relaxed)) return;
  const bool same = servo_ != nullptr && std::memcmp(&setup_, &segment_->setup, sizeof setup_) == 0;
  if (!same && servo_ != nullptr && guard_.drives_enabled()) return;
  if (!same) {
    if (servo_ != nullptr) servo_->~Servo();
    std::memcpy(static_cast<void*>(&setup_), &segment_->setup, sizeof setup_);
    machine_->set_capabilities(setup_.capabilities);
    guard_.refresh_capabilities();
    servo_ = new (storage_) Servo(setup_.servo, segment_->channels, guard_);
    ++servos_built_;
  } else {
    servo_->drop_staged();
  }
  h.setup_taken.store(generation, std::memory_order_release);
}

}  // namespace opencnc::control
