// SPDX-License-Identifier: GPL-3.0-or-later
// The controller's heartbeat as the tick sees it, and the MachineIO decorator that turns a stopped
// heartbeat into the servo's controlled stop (the power-loss path: abort ramp, then a fault).
#pragma once

#include <atomic>
#include <cstdint>

#include "opencnc/machine/machine_io.hpp"

namespace opencnc::control {

/// Watches a counter the controller process increments. Alive from the first change until
/// `timeout_ticks` periods pass without one; alive again at the next change. Servo thread;
/// real-time safe.
class HeartbeatWatch {
 public:
  /// Setup thread. `beat` must outlive the watch (it lives in shared memory).
  HeartbeatWatch(const std::atomic<std::uint64_t>& beat, std::uint32_t timeout_ticks) noexcept
      : beat_(&beat), timeout_ticks_(timeout_ticks == 0 ? 1 : timeout_ticks) {}
  /// Sets the timeout (the thread's period may only be known at its first call). Servo thread.
  void set_timeout(std::uint32_t timeout_ticks) noexcept {
    timeout_ticks_ = timeout_ticks == 0 ? 1 : timeout_ticks;
  }
  /// Once per period, before the machine's inputs are read. Returns alive(). Servo thread.
  bool update() noexcept;
  /// A heartbeat was seen within the last timeout_ticks periods. Servo thread.
  bool alive() const noexcept { return alive_; }
  /// Times the heartbeat stopped after having been alive. Servo thread.
  std::uint32_t losses() const noexcept { return losses_; }

 private:
  const std::atomic<std::uint64_t>* beat_;
  std::uint32_t timeout_ticks_;
  std::uint64_t last_ = 0;
  std::uint32_t quiet_ticks_ = 0;
  bool alive_ = false;
  std::uint32_t losses_ = 0;
};

/// A machine backend whose capabilities are handed over at run time (the HAL pins exist from load
/// time; what is wired comes with the controller's set-up).
class ConfigurableMachine : public machine::MachineIO {
 public:
  /// Servo thread, between periods (the servo is rebuilt after it); real-time safe.
  virtual void set_capabilities(const machine::MachineCapabilities& caps) noexcept = 0;
};

/// Decorates a backend: while the heartbeat is not alive the servo reads "mains lost", which it
/// answers with its controlled stop (a run aborted along its path at the abort deceleration,
/// jogs and homing brought to rest) and then the PowerLoss fault with the drives disabled. The
/// backend's own power monitor, if any, still counts.
class HeartbeatGuard final : public machine::MachineIO {
 public:
  /// Setup thread. `inner` and `watch` must outlive the guard.
  HeartbeatGuard(machine::MachineIO& inner, const HeartbeatWatch& watch) noexcept
      : inner_(&inner), watch_(&watch) {
    refresh_capabilities();
  }
  /// Takes the backend's power monitor anew after its capabilities changed. Servo thread;
  /// real-time safe.
  void refresh_capabilities() noexcept;
  /// The backend's, with the power monitor the heartbeat needs. Setup thread.
  machine::MachineCapabilities capabilities() const noexcept override;
  /// Servo thread; real-time safe.
  void read(machine::MachineInputs& in) noexcept override;
  /// Servo thread; real-time safe.
  void write(const machine::MachineOutputs& out) noexcept override;
  /// Some joint's drive was enabled in the last outputs. Servo thread.
  bool drives_enabled() const noexcept { return drives_enabled_; }

 private:
  machine::MachineIO* inner_;
  const HeartbeatWatch* watch_;
  bool inner_power_monitor_ = false;
  bool drives_enabled_ = false;
};

}  // namespace opencnc::control
