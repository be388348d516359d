// SPDX-License-Identifier: GPL-3.0-or-later
// connect::Fleet — every machine an MQTT broker knows, as the shop's fleet view shows them: read
// from the topics the machines' publishers write (docs/connectivity.md, "MQTT"), nothing else.
// connect::FleetWatcher subscribes to a broker and keeps a Fleet up to date.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/connect/mqtt_publisher.hpp"

struct mosquitto;
struct mosquitto_message;

namespace opencnc::connect {

/// An active condition of a machine: a warning or a fault.
struct FleetAlarm {
  std::string item;   ///< the data item's id ("system", "x_travel")
  std::string level;  ///< "Warning" or "Fault"
  std::string native_code;
  std::string message;
};

/// One machine as the fleet view shows it. Values are MTConnect's words ("UNAVAILABLE" when
/// unknown); `progress` < 0 when its publisher does not say.
struct FleetMachine {
  std::string uuid, name;
  std::string hmi;  ///< the machine's own HMI ("" = not said)
  std::string availability = "UNAVAILABLE";
  std::string execution = "UNAVAILABLE", mode = "UNAVAILABLE", program = "UNAVAILABLE", line = "UNAVAILABLE",
              part_count = "UNAVAILABLE", tool = "UNAVAILABLE", emergency_stop = "UNAVAILABLE",
              feed = "UNAVAILABLE", spindle_speed = "UNAVAILABLE", spindle_load = "UNAVAILABLE";
  double progress = -1;  ///< 0 … 1 of the program's path
  std::vector<FleetAlarm> alarms;
  std::int64_t last_seen_ms = 0;  ///< when the last message of it arrived (ms since 1970 UTC)
  std::uint64_t instance_id = 0;  ///< its agent's instance: a restarted machine counts anew
  // What arrived of its samples: sequence numbers that came twice (ignored) and gaps reported.
  std::uint64_t next_sequence = 0, duplicates = 0, gaps = 0, gap_observations = 0;
};

/// The fleet built from messages. Not thread-safe (FleetWatcher serialises it).
class Fleet {
 public:
  explicit Fleet(std::string topic_prefix = "MTConnect");
  /// One message of `<prefix>/<Probe|Current|Sample|Availability>/<uuid>`, arrived at `now_ms`.
  /// Returns false (and counts it) for a payload that is not what the topic carries; other
  /// topics are ignored (true).
  bool take(std::string_view topic, std::string_view payload, std::int64_t now_ms);
  /// The machines, by name.
  std::vector<FleetMachine> machines() const;
  /// The fleet view's JSON: {"machines": [...], "malformed": N, "now": ms}, and "broker": {"url",
  /// "connected"} when `broker_url` is given.
  std::string json(std::int64_t now_ms, std::string_view broker_url = {}, bool connected = false) const;
  std::uint64_t malformed() const noexcept { return malformed_; }

 private:
  struct Item {
    std::string category, type, sub_type, component;
  };
  struct Machine {
    FleetMachine view;
    std::map<std::string, Item, std::less<>> items;
    std::map<std::string, std::string, std::less<>> values;
    std::map<std::string, std::map<std::string, FleetAlarm>, std::less<>> conditions;  // item → code →
  };
  friend struct FleetCodec;  // the payloads' reader (fleet.cpp)

  std::string prefix_;
  std::map<std::string, Machine, std::less<>> machines_;  // by uuid
  std::uint64_t malformed_ = 0;
};

struct FleetOptions {
  MqttAddress broker;
  std::string topic_prefix = "MTConnect";
  int keepalive_s = 5;
};

/// A subscriber to `<prefix>/#` on the broker (libmosquitto; reconnects on its own) keeping a Fleet.
class FleetWatcher {
 public:
  explicit FleetWatcher(FleetOptions options);
  ~FleetWatcher();
  FleetWatcher(const FleetWatcher&) = delete;
  FleetWatcher& operator=(const FleetWatcher&) = delete;

  void start();
  void stop();
  bool connected() const noexcept { return connected_; }
  std::vector<FleetMachine> machines() const;
  /// Fleet::json with the broker's state: {"broker": {"url", "connected"}, ...}. Any thread.
  std::string json() const;

  /// Milliseconds since 1970 UTC.
  static std::int64_t wall_ms();

 private:
  static void on_connect(struct mosquitto*, void* self, int rc);
  static void on_disconnect(struct mosquitto*, void* self, int rc);
  static void on_message(struct mosquitto*, void* self, const struct mosquitto_message* msg);

  FleetOptions options_;
  struct mosquitto* client_ = nullptr;
  std::atomic<bool> connected_{false};
  bool running_ = false;
  mutable std::mutex mutex_;  // guards fleet_
  Fleet fleet_;
};

}  // namespace opencnc::connect
