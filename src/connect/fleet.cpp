// SPDX-License-Identifier: GPL-3.0-or-later
// The fleet view's model: the machines' MQTT topics read back into one row per machine.
#include "opencnc/connect/fleet.hpp"

#include <fmt/format.h>
#include <mosquitto.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace opencnc::connect {

using Json = nlohmann::json;

/// Reads the payloads into a Fleet's machines.
struct FleetCodec {
  using Machine = Fleet::Machine;

  static std::string text(const Json& j, const char* key, std::string fallback = {}) {
    const auto it = j.find(key);
    return it != j.end() && it->is_string() ? it->get<std::string>() : fallback;
  }

  static void probe(Machine& m, const Json& j) {
    m.view.name = text(j, "device", m.view.name);
    m.view.hmi = text(j, "hmi");
    m.items.clear();
    for (const Json& i : j.at("dataItems"))
      m.items[i.at("id").get<std::string>()] =
          Fleet::Item{text(i, "category"), text(i, "type"), text(i, "subType"), text(i, "component")};
  }

  static void observation(Machine& m, const Json& o) {
    const std::string id = o.at("dataItemId").get<std::string>();
    if (text(o, "category") == "CONDITION") {
      auto& active = m.conditions[id];
      const std::string level = text(o, "level"), code = text(o, "nativeCode");
      if (level == "Warning" || level == "Fault")
        active[code] = FleetAlarm{id, level, code, text(o, "message")};
      else if (code.empty())
        active.clear();  // Normal or Unavailable for the whole item
      else
        active.erase(code);
    } else {
      m.values[id] = text(o, "value", "UNAVAILABLE");
    }
  }

  /// The row's fields from the items' values, found by their MTConnect types.
  static void summarise(Machine& m) {
    FleetMachine& v = m.view;
    std::string spindle_component;
    for (const auto& [id, item] : m.items)
      if (item.type == "ROTARY_MODE") spindle_component = item.component;
    auto value = [&](std::string_view id) {
      const auto it = m.values.find(id);
      return it == m.values.end() ? std::string("UNAVAILABLE") : it->second;
    };
    for (const auto& [id, item] : m.items) {
      const std::string& t = item.type;
      if (t == "EXECUTION")
        v.execution = value(id);
      else if (t == "CONTROLLER_MODE")
        v.mode = value(id);
      else if (t == "PROGRAM")
        v.program = value(id);
      else if (t == "LINE_NUMBER")
        v.line = value(id);
      else if (t == "PART_COUNT")
        v.part_count = value(id);
      else if (t == "TOOL_NUMBER")
        v.tool = value(id);
      else if (t == "EMERGENCY_STOP")
        v.emergency_stop = value(id);
      else if (t == "PATH_FEEDRATE" && item.sub_type == "ACTUAL")
        v.feed = value(id);
      else if (t == "ROTARY_VELOCITY" && item.sub_type == "ACTUAL")
        v.spindle_speed = value(id);
      else if (t == "LOAD" && !spindle_component.empty() && item.component == spindle_component)
        v.spindle_load = value(id);
    }
    v.alarms.clear();
    for (const auto& [id, active] : m.conditions)
      for (const auto& [code, alarm] : active) v.alarms.push_back(alarm);
  }
};

Fleet::Fleet(std::string topic_prefix) : prefix_(std::move(topic_prefix)) {}

bool Fleet::take(std::string_view topic, std::string_view payload, std::int64_t now_ms) {
  // <prefix>/<kind>/<uuid>
  if (!topic.starts_with(prefix_) || topic.size() <= prefix_.size() || topic[prefix_.size()] != '/')
    return true;
  const std::string_view rest = topic.substr(prefix_.size() + 1);
  const auto slash = rest.find('/');
  if (slash == std::string_view::npos) return true;
  const std::string_view kind = rest.substr(0, slash), uuid = rest.substr(slash + 1);
  if (uuid.empty() || uuid.find('/') != std::string_view::npos) return true;
  if (kind != "Probe" && kind != "Current" && kind != "Sample" && kind != "Availability") return true;
  if (payload.empty()) return true;  // a retained message cleared: nothing to learn

  auto it = machines_.find(uuid);
  if (it == machines_.end()) {
    it = machines_.emplace(std::string(uuid), Machine{}).first;
    it->second.view.uuid = std::string(uuid);
    it->second.view.name = std::string(uuid);
  }
  Machine& m = it->second;
  try {
    if (kind == "Availability") {
      if (payload != "AVAILABLE" && payload != "UNAVAILABLE") throw std::invalid_argument("availability");
      m.view.availability = std::string(payload);
    } else {
      const Json j = Json::parse(payload);
      if (const std::uint64_t instance = j.value("instanceId", std::uint64_t{0});
          instance != m.view.instance_id) {
        // The machine restarted: its sequence numbers begin again.
        m.view.instance_id = instance;
        m.view.next_sequence = 0;
        m.values.clear();
        m.conditions.clear();
      }
      if (kind == "Probe") {
        FleetCodec::probe(m, j);
      } else if (kind == "Current") {
        // The retained state: what it says replaces what is known, unless samples went further.
        const std::uint64_t next = j.at("nextSequence").get<std::uint64_t>();
        if (next >= m.view.next_sequence) {
          m.values.clear();
          m.conditions.clear();
          for (const Json& o : j.at("observations")) FleetCodec::observation(m, o);
          m.view.next_sequence = next;
        }
        if (const auto p = j.find("progress"); p != j.end() && p->is_number())
          m.view.progress = p->get<double>();
      } else {  // Sample
        if (const auto g = j.find("gap"); g != j.end()) {
          ++m.view.gaps;
          m.view.gap_observations += g->at("count").get<std::uint64_t>();
        }
        for (const Json& o : j.at("observations")) {
          const std::uint64_t s = o.at("sequence").get<std::uint64_t>();
          if (s < m.view.next_sequence) {  // sent again after a reconnection: have it
            ++m.view.duplicates;
            continue;
          }
          FleetCodec::observation(m, o);
          m.view.next_sequence = s + 1;
        }
      }
    }
  } catch (const std::exception&) {
    ++malformed_;
    return false;
  }
  m.view.last_seen_ms = now_ms;
  FleetCodec::summarise(m);
  return true;
}

std::vector<FleetMachine> Fleet::machines() const {
  std::vector<FleetMachine> out;
  for (const auto& [uuid, m] : machines_) out.push_back(m.view);
  std::stable_sort(out.begin(), out.end(),
                   [](const FleetMachine& a, const FleetMachine& b) { return a.name < b.name; });
  return out;
}

std::string Fleet::json(std::int64_t now_ms, std::string_view broker_url, bool connected) const {
  Json list = Json::array();
  for (const FleetMachine& v : machines()) {
    Json alarms = Json::array();
    for (const FleetAlarm& a : v.alarms)
      alarms.push_back(
          {{"item", a.item}, {"level", a.level}, {"nativeCode", a.native_code}, {"message", a.message}});
    Json row{{"uuid", v.uuid},
             {"name", v.name},
             {"hmi", v.hmi},
             {"availability", v.availability},
             {"execution", v.execution},
             {"mode", v.mode},
             {"program", v.program},
             {"line", v.line},
             {"partCount", v.part_count},
             {"tool", v.tool},
             {"emergencyStop", v.emergency_stop},
             {"feed", v.feed},
             {"spindleSpeed", v.spindle_speed},
             {"spindleLoad", v.spindle_load},
             {"alarms", std::move(alarms)},
             {"lastSeenMs", v.last_seen_ms},
             {"instanceId", v.instance_id},
             {"nextSequence", v.next_sequence},
             {"duplicates", v.duplicates},
             {"gaps", v.gaps},
             {"gapObservations", v.gap_observations}};
    row["progress"] = v.progress >= 0 ? Json(v.progress) : Json(nullptr);
    list.push_back(std::move(row));
  }
  Json j{{"machines", std::move(list)}, {"malformed", malformed_}, {"now", now_ms}};
  if (!broker_url.empty()) j["broker"] = {{"url", broker_url}, {"connected", connected}};
  return j.dump();
}

// --- The watcher --------------------------------------------------------------------------------

std::int64_t FleetWatcher::wall_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

FleetWatcher::FleetWatcher(FleetOptions options)
    : options_(std::move(options)), fleet_(options_.topic_prefix) {
  if (options_.keepalive_s < 5) throw std::invalid_argument("fleet: the keep-alive must be at least 5 s");
  static const int once = [] { return mosquitto_lib_init(); }();
  (void)once;
}

FleetWatcher::~FleetWatcher() {
  stop();
}

void FleetWatcher::start() {
  if (running_) return;
  client_ = mosquitto_new(nullptr, true, this);
  if (client_ == nullptr) throw std::runtime_error("fleet: libmosquitto could not make a client");
  mosquitto_connect_callback_set(client_, &FleetWatcher::on_connect);
  mosquitto_disconnect_callback_set(client_, &FleetWatcher::on_disconnect);
  mosquitto_message_callback_set(client_, &FleetWatcher::on_message);
  // The broker may be away: libmosquitto's loop reconnects, backing off from 1 to 8 s.
  mosquitto_reconnect_delay_set(client_, 1, 8, true);
  mosquitto_connect_async(client_, options_.broker.host.c_str(), options_.broker.port, options_.keepalive_s);
  mosquitto_loop_start(client_);
  running_ = true;
}

void FleetWatcher::stop() {
  if (!running_) return;
  mosquitto_disconnect(client_);
  mosquitto_loop_stop(client_, true);
  mosquitto_destroy(client_);
  client_ = nullptr;
  running_ = false;
  connected_ = false;
}

void FleetWatcher::on_connect(struct mosquitto* m, void* self, int rc) {
  auto* w = static_cast<FleetWatcher*>(self);
  if (rc != 0) return;
  w->connected_ = true;
  // Subscribing again at each connection: the retained device, state and availability arrive anew.
  mosquitto_subscribe(m, nullptr, fmt::format("{}/#", w->options_.topic_prefix).c_str(), 1);
}

void FleetWatcher::on_disconnect(struct mosquitto*, void* self, int) {
  static_cast<FleetWatcher*>(self)->connected_ = false;
}

void FleetWatcher::on_message(struct mosquitto*, void* self, const struct mosquitto_message* msg) {
  auto* w = static_cast<FleetWatcher*>(self);
  const std::string_view payload(static_cast<const char*>(msg->payload),
                                 static_cast<std::size_t>(msg->payloadlen));
  std::lock_guard lock(w->mutex_);
  w->fleet_.take(msg->topic, payload, wall_ms());
}

std::vector<FleetMachine> FleetWatcher::machines() const {
  std::lock_guard lock(mutex_);
  return fleet_.machines();
}

std::string FleetWatcher::json() const {
  const std::string url = fmt::format("mqtt://{}:{}", options_.broker.host, options_.broker.port);
  std::lock_guard lock(mutex_);
  return fleet_.json(wall_ms(), url, connected_.load());
}

}  // namespace opencnc::connect
