// SPDX-License-Identifier: GPL-3.0-or-later
// Sampling the controller's status into the agent on a thread of its own.
#include "opencnc/connect/status_sampler.hpp"

namespace opencnc::connect {

StatusSampler::StatusSampler(Agent& agent, StatusFn status, ToolsFn tools, SamplerOptions options)
    : agent_(agent), status_(std::move(status)), tools_(std::move(tools)), options_(options) {}

StatusSampler::~StatusSampler() {
  stop();
}

std::int64_t StatusSampler::wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void StatusSampler::start() {
  if (thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = false;
  }
  thread_ = std::thread([this] { run(); });
}

void StatusSampler::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
  agent_.mark_unavailable(wall_us());
}

void StatusSampler::run() {
  auto next_tools = std::chrono::steady_clock::now();
  auto next = std::chrono::steady_clock::now();
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    agent_.observe(status_(), wall_us());
    if (tools_ && std::chrono::steady_clock::now() >= next_tools) {
      agent_.set_tools(tools_(), wall_us());
      next_tools = std::chrono::steady_clock::now() + options_.tools_period;
    }
    lock.lock();
    // A fixed rate, not a fixed pause: a slow sample does not stretch the period after it.
    next += options_.period;
    const auto now = std::chrono::steady_clock::now();
    if (next < now) next = now;
    wake_.wait_until(lock, next, [this] { return stopping_; });
  }
}

}  // namespace opencnc::connect
