// SPDX-License-Identifier: GPL-3.0-or-later
// SharedServoHost — runs the servo tick over a SharedSegment in the process that owns the machine
// (the HAL component): takes the controller's set-up, watches its heartbeat, and keeps the
// machine's outputs safe (drives disabled, e-stop chain open) while no set-up has been taken.
#pragma once

#include <cstdint>
#include <new>

#include "opencnc/control/heartbeat.hpp"
#include "opencnc/control/servo.hpp"
#include "opencnc/control/shared_channels.hpp"
#include "opencnc/control/tickable.hpp"

namespace opencnc::control {

class SharedServoHost final : public Tickable {
 public:
  /// Setup thread. `segment` (initialised by its creator) and `machine` must outlive the host.
  SharedServoHost(SharedSegment& segment, ConfigurableMachine& machine) noexcept;
  ~SharedServoHost() override;
  SharedServoHost(const SharedServoHost&) = delete;
  SharedServoHost& operator=(const SharedServoHost&) = delete;

  /// One period: heartbeat, a pending set-up (taken while no drive is enabled), then the servo's
  /// tick or safe outputs. Servo thread; real-time safe, allocates nothing. Always true.
  bool tick() noexcept override;

  /// A set-up has been taken and the servo runs. Servo thread.
  bool running() const noexcept { return servo_ != nullptr; }
  /// The servo (running() only). Servo thread.
  const Servo* servo() const noexcept { return servo_; }
  /// How many servos were built from set-ups so far (an identical set-up keeps the servo: the
  /// count stays). Servo thread.
  std::uint64_t servos_built() const noexcept { return servos_built_; }
  /// Periods without a heartbeat before the machine stops. Servo thread.
  void set_heartbeat_timeout(std::uint32_t ticks) noexcept { watch_.set_timeout(ticks); }
  /// Servo thread.
  const HeartbeatWatch& heartbeat() const noexcept { return watch_; }

 private:
  void take_setup() noexcept;

  SharedSegment* segment_;
  ConfigurableMachine* machine_;
  HeartbeatWatch watch_;
  HeartbeatGuard guard_;
  SharedSetup setup_{};  ///< the set-up the servo was built from
  Servo* servo_ = nullptr;
  std::uint64_t servos_built_ = 0;
  alignas(Servo) unsigned char storage_[sizeof(Servo)];
};

}  // namespace opencnc::control
