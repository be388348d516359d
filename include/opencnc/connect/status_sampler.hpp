// SPDX-License-Identifier: GPL-3.0-or-later
// connect::StatusSampler — feeds an agent on a thread of its own: the controller's status at a fixed
// rate and the tool table now and then, stamped with the wall clock; at stop, the machine UNAVAILABLE.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "opencnc/connect/agent.hpp"

namespace opencnc::connect {

struct SamplerOptions {
  std::chrono::milliseconds period{100};         ///< how often the status is read
  std::chrono::milliseconds tools_period{2000};  ///< how often the tool table is read
};

class StatusSampler {
 public:
  using StatusFn = std::function<controller::ControllerStatus()>;
  using ToolsFn = std::function<std::vector<ToolAsset>()>;
  /// `status` (any thread may call it: Controller::status), `tools` (may be empty: no assets).
  /// The agent must outlive the sampler.
  StatusSampler(Agent& agent, StatusFn status, ToolsFn tools, SamplerOptions options = {});
  ~StatusSampler();
  StatusSampler(const StatusSampler&) = delete;
  StatusSampler& operator=(const StatusSampler&) = delete;

  void start();
  /// Stops sampling and marks the machine UNAVAILABLE. Idempotent.
  void stop();

  /// µs since 1970 UTC now (the observations' stamps).
  static std::int64_t wall_us();

 private:
  void run();

  Agent& agent_;
  StatusFn status_;
  ToolsFn tools_;
  SamplerOptions options_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
};

}  // namespace opencnc::connect
