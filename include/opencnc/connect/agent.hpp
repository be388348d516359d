// SPDX-License-Identifier: GPL-3.0-or-later
// connect::Agent — an MTConnect agent for one machine (docs/connectivity.md): samples the
// controller's status into a bounded, sequence-numbered buffer and answers /probe, /current,
// /sample and /assets with MTConnect 2.7 documents (MTConnectError for bad requests).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/connect/contribution.hpp"
#include "opencnc/connect/device_model.hpp"
#include "opencnc/connect/observations.hpp"
#include "opencnc/controller/controller_status.hpp"

namespace opencnc::config {
struct MachineProfile;
}

namespace opencnc::connect {

struct AgentOptions {
  std::string sender = "opencnc";  ///< the documents' Header sender (the host's name)
  /// The device's name ("" = the profile's): machines of one profile in one shop need their own.
  /// Its uuid is "opencnc-<name>".
  std::string device_name;
  /// Tells clients the agent restarted (sequence numbers began again): the start time, say.
  std::uint64_t instance_id = 1;
  std::size_t buffer_size = 131072;  ///< observations kept (MTConnect's bufferSize)
  std::size_t max_count = 10000;     ///< the largest `count` a /sample may ask for
  /// When the agent starts (µs since 1970 UTC): every data item is UNAVAILABLE from then until
  /// its first value, each with a sequence number of its own.
  std::int64_t start_us = 0;
};

/// One tool of the tool table as a CuttingTool asset.
struct ToolAsset {
  int number = 0;  ///< T
  int pocket = 0;  ///< P (0: none)
  double length_mm = 0;
  double diameter_mm = 0;
  std::string comment;
  std::int64_t changed_us = 0;  ///< when it last changed (its asset timestamp)
};

/// A request the agent answers: the path below the agent's root and the decoded query.
struct AgentRequest {
  std::string path;
  std::map<std::string, std::string, std::less<>> query;
};

/// `target` ("/sample?from=3&path=%2F%2FAxes") split and percent-decoded ('+' is a space).
AgentRequest parse_agent_request(std::string_view target);

struct AgentResponse {
  int status = 200;
  std::string content_type = "text/xml; charset=utf-8";
  std::string body;
};

/// What a /sample answered: its document and where the next one begins (MTConnect's
/// nextSequence of the answer: the client's next `from`).
struct SampleAnswer {
  AgentResponse response;
  std::uint64_t next_from = 0;
  bool empty = true;  ///< no observation in the answer
};

class Agent {
 public:
  Agent(DeviceModel model, std::vector<std::unique_ptr<Contribution>> contributions, AgentOptions options);
  /// The device a profile describes, observed by the contributions it calls for.
  static std::unique_ptr<Agent> for_profile(const config::MachineProfile& profile, AgentOptions options);

  /// Samples `status` at `time_us` (µs since 1970 UTC): every value that changed becomes an
  /// observation. The first call also marks the device AVAILABLE. Any one thread at a time.
  void observe(const controller::ControllerStatus& status, std::int64_t time_us);
  /// The controller went away: AVAILABILITY UNAVAILABLE, every other item UNAVAILABLE.
  void mark_unavailable(std::int64_t time_us);
  /// Replaces the tool assets (the tool store's tools); changed ones get ASSET_CHANGED.
  void set_tools(std::vector<ToolAsset> tools, std::int64_t time_us);

  /// Answers a request (any thread, concurrently with observe()).
  AgentResponse respond(const AgentRequest& request, std::int64_t now_us) const;
  /// /sample with its parameters (used by respond() and by the server's streaming of
  /// `interval`): `from` 0 = the first sequence.
  SampleAnswer sample(const AgentRequest& request, std::int64_t now_us) const;
  /// The next sequence number (observations are < it). Any thread.
  std::uint64_t next_sequence() const;
  /// The oldest sequence number still in the buffer. Any thread.
  std::uint64_t first_sequence() const;
  /// Observations from `from` on (the oldest retained when `from` is older: `*first` says where the
  /// answer begins), at most `max`. Any thread.
  std::vector<Observation> observations(std::uint64_t from, std::size_t max,
                                        std::uint64_t* first = nullptr) const;
  /// Every item's current observation (each active condition of a condition item, else its last),
  /// in model order: what a new SHDR client or a retained MQTT message starts from; `*next` (if
  /// given) the next sequence at that instant, read under the same lock, so that a reader going on
  /// from it misses nothing. Any thread.
  std::vector<Observation> snapshot(std::uint64_t* next = nullptr) const;
  const AgentOptions& options() const noexcept { return options_; }
  /// The running program's progress at the last sample (0 … 1 of its path; MTConnect has no data
  /// item for it, the fleet view's MQTT state carries it). Any thread.
  double progress() const;

  const DeviceModel& model() const noexcept { return model_; }

 private:
  AgentResponse probe(const AgentRequest& request, std::int64_t now_us) const;
  AgentResponse current(const AgentRequest& request, std::int64_t now_us) const;
  AgentResponse assets(const AgentRequest& request, std::int64_t now_us) const;
  AgentResponse error(std::string_view code, std::string message, const AgentRequest& request,
                      std::int64_t now_us, std::string_view parameter = {}) const;
  void add(std::size_t item, Level level, std::string native_code, std::string value, std::int64_t time_us);

  DeviceModel model_;
  std::vector<std::unique_ptr<Contribution>> contributions_;
  AgentOptions options_;
  std::size_t availability_ = 0, asset_changed_ = 0, asset_removed_ = 0;
  mutable std::mutex mutex_;  // guards buffer_, tools_, tools_changed_us_, observed_
  ObservationBuffer buffer_;
  std::vector<ToolAsset> tools_;
  bool observed_ = false;
  double progress_ = 0;
};

}  // namespace opencnc::connect
