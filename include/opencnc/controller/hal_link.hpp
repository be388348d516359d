// SPDX-License-Identifier: GPL-3.0-or-later
// HalLink — the controller's side of a servo tick that runs in another process (LinuxCNC's HAL,
// opencnc_rt.so): attaches to its shared memory, checks it runs at the profile's period, hands
// the profile's set-up over and beats the heartbeat from a thread of its own while it lives.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/control/channels.hpp"
#include "opencnc/control/shared_memory.hpp"

namespace opencnc::controller {

class HalLink {
 public:
  /// Attaches to the segment `name` and hands `profile`'s set-up to the tick, waiting at most
  /// `wait` for the tick to run and to take it. Nothing on failure, with `error` saying why (no
  /// component, another build, its thread not running, another period, another controller
  /// attached, a set-up refused because the drives are on). Setup thread.
  static std::unique_ptr<HalLink> attach(const std::string& name, const config::MachineProfile& profile,
                                         std::string& error,
                                         std::chrono::milliseconds wait = std::chrono::milliseconds(3000));
  ~HalLink();
  HalLink(const HalLink&) = delete;
  HalLink& operator=(const HalLink&) = delete;

  /// The channels to give the Controller. Controller thread.
  control::ServoChannels& channels() noexcept { return memory_->segment().channels; }
  /// The tick's header (heartbeat, losses, ticks). Any thread.
  const control::SharedHeader& header() const noexcept { return memory_->segment().header; }

 private:
  explicit HalLink(std::unique_ptr<control::SegmentMapping> memory) noexcept : memory_(std::move(memory)) {}
  void beat_every(std::chrono::nanoseconds interval);

  std::unique_ptr<control::SegmentMapping> memory_;
  std::atomic<bool> stop_{false};
  std::thread beat_;
};

}  // namespace opencnc::controller
