// SPDX-License-Identifier: GPL-3.0-or-later
// connect::MqttPublisher — the agent's observations published to an MQTT broker (libmosquitto):
// QoS 1 batches with sequence numbers, the device and its current state retained, a last will that
// marks the machine unavailable, reconnection with back-off, and a bounded queue while the broker
// is away whose losses are counted and published when it returns (docs/connectivity.md, "MQTT").
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "opencnc/connect/agent.hpp"
#include "opencnc/connect/json_messages.hpp"

struct mosquitto;

namespace opencnc::connect {

/// `mqtt://HOST[:PORT]` (port 1883 when left out).
struct MqttAddress {
  std::string host;
  int port = 1883;
};
/// The address in `url`, or nullopt with the reason in `error`.
std::optional<MqttAddress> parse_mqtt_url(std::string_view url, std::string* error);

struct MqttOptions {
  MqttAddress broker;
  std::string topic_prefix = "MTConnect";
  int keepalive_s = 5;  ///< ≥ 5 (libmosquitto's least); the broker sends the will after 1.5× this of silence
  std::size_t queue_limit = 200000;  ///< observations held unacknowledged; the oldest go first beyond it
  std::size_t batch_size = 500;      ///< observations per message at most
  int poll_ms = 50;                  ///< how often the agent's new observations are read
  int current_every_ms = 1000;       ///< how often the retained current state is refreshed
  int reconnect_min_ms = 250, reconnect_max_ms = 8000;  ///< the back-off doubles from min to max
  std::string hmi_url;  ///< the machine's own HMI, told to the fleet view in the device message ("" = none)
};

struct MqttStats {
  bool connected = false;
  std::uint64_t connects = 0;       ///< successful connections (1 + reconnections)
  std::uint64_t batches_acked = 0;  ///< batches the broker acknowledged (PUBACK)
  std::uint64_t observations_acked = 0;
  std::uint64_t dropped = 0;        ///< observations never published (queue full, buffer turned over)
  std::uint64_t queued = 0;         ///< observations waiting for the broker now
  std::uint64_t next_sequence = 0;  ///< the next observation to be queued
  std::string last_error;           ///< why the last connection failed or was lost ("" = none yet)
};

/// The topics of a device: `<prefix>/<kind>/<uuid>` for kind Probe, Current, Sample, Availability.
std::string mqtt_topic(std::string_view prefix, std::string_view kind, std::string_view uuid);

class MqttPublisher {
 public:
  /// Publishes `agent`'s observations from its next sequence on. The agent must outlive it.
  MqttPublisher(const Agent& agent, MqttOptions options);
  ~MqttPublisher();
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  /// Starts the publishing thread (it connects, and reconnects, on its own).
  void start();
  /// A clean stop: what is queued is offered for `drain_ms`, the availability is published
  /// UNAVAILABLE (a clean disconnect sends no will), and the connection closed.
  void stop(int drain_ms = 1000);
  MqttStats stats() const;

 private:
  struct Batch {
    std::uint64_t first = 0, last = 0, count = 0;
    std::vector<Observation> observations;
    Gap gap;       ///< dropped just before it
    int mid = -1;  ///< the message id while sent and not acknowledged; −1: to be sent
  };
  void run();
  void queue_new_observations();
  void publish_pending();
  void publish_current(bool force);
  void connect_client();
  void drop_client();
  static void on_connect(struct mosquitto*, void* self, int rc);
  static void on_disconnect(struct mosquitto*, void* self, int rc);
  static void on_publish(struct mosquitto*, void* self, int mid);

  const Agent& agent_;
  MqttOptions options_;
  std::string sample_topic_, current_topic_, probe_topic_, availability_topic_;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  mutable std::mutex mutex_;  // guards everything below, shared with libmosquitto's network thread
  std::condition_variable wake_;
  struct mosquitto* client_ = nullptr;
  bool connected_ = false, lost_ = false, just_connected_ = false;
  std::deque<Batch> pending_;
  std::uint64_t next_ = 0;  ///< the next sequence to read from the agent
  std::uint64_t queued_ = 0, dropped_ = 0;
  Gap gap_;                                 ///< dropped before the next batch to be made
  std::uint64_t current_published_at_ = 0;  ///< the next sequence at the last retained current state
  std::int64_t current_due_ms_ = 0;
  int backoff_ms_ = 0;
  std::int64_t reconnect_at_ms_ = 0;
  MqttStats stats_;
};

}  // namespace opencnc::connect
