// SPDX-License-Identifier: GPL-3.0-or-later
// The controller's link to a servo tick in LinuxCNC's HAL: attach, checks, set-up, heartbeat.
#include "opencnc/controller/hal_link.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "opencnc/controller/servo_setup.hpp"

namespace opencnc::controller {
namespace {

using Clock = std::chrono::steady_clock;

bool wait_for(const std::function<bool()>& done, std::chrono::milliseconds limit) {
  const auto end = Clock::now() + limit;
  while (!done()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

bool other_controller(const control::SharedHeader& h) {
  const auto pid = static_cast<pid_t>(h.controller_pid.load());
  return pid != 0 && pid != ::getpid() && h.controller_alive.load() && ::kill(pid, 0) == 0;
}

}  // namespace

std::unique_ptr<HalLink> HalLink::attach(const std::string& name, const config::MachineProfile& profile,
                                         std::string& error, std::chrono::milliseconds wait) {
  auto memory = control::SegmentMapping::attach(name, error);
  if (!memory) return nullptr;
  control::SharedSegment& s = memory->segment();
  control::SharedHeader& h = s.header;
  if (!wait_for([&] { return h.ticks.load() > 0 && h.period_ns > 0; }, wait)) {
    error = fmt::format(
        "the HAL component behind {} does not tick: add its function to a thread and start it "
        "(addf opencnc.update servo-thread; start)",
        name);
    return nullptr;
  }
  const auto period_ns = static_cast<std::int64_t>(std::llround(profile.servo_period_s * 1e9));
  if (h.period_ns != period_ns) {
    error =
        fmt::format("the HAL thread runs every {} ns, the profile's servo_period_s is {} ns: they must agree",
                    h.period_ns, period_ns);
    return nullptr;
  }
  if (other_controller(h)) {
    error = fmt::format("another controller (pid {}) is attached to {}", h.controller_pid.load(), name);
    return nullptr;
  }
  std::unique_ptr<HalLink> link(new HalLink(std::move(memory)));
  h.controller_pid.store(static_cast<std::uint32_t>(::getpid()));
  // Beat well within the tick's timeout (5 beats per timeout, at most every 10 ms).
  const auto timeout =
      std::chrono::nanoseconds(period_ns * std::max<std::uint32_t>(1, h.heartbeat_timeout_ticks.load()));
  link->beat_every(std::min<std::chrono::nanoseconds>(timeout / 5, std::chrono::milliseconds(10)));
  drain_stale_output(s);
  const std::uint64_t generation = offer_setup(s, shared_setup(profile));
  if (!wait_for([&] { return setup_taken(s, generation); }, wait)) {
    error = fmt::format(
        "the tick behind {} does not take this profile's set-up while its drives are enabled "
        "(switch the machine off, or e-stop, first)",
        name);
    return nullptr;
  }
  return link;
}

void HalLink::beat_every(std::chrono::nanoseconds interval) {
  std::atomic<std::uint64_t>& beat = memory_->segment().header.heartbeat;
  beat.fetch_add(1);
  beat_ = std::thread([this, &beat, interval] {
    while (!stop_.load(std::memory_order_relaxed)) {
      beat.fetch_add(1, std::memory_order_release);
      std::this_thread::sleep_for(interval);
    }
  });
}

HalLink::~HalLink() {
  stop_ = true;
  if (beat_.joinable()) beat_.join();
  memory_->segment().header.controller_pid.store(0);
}

}  // namespace opencnc::controller
