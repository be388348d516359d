// SPDX-License-Identifier: GPL-3.0-or-later
// The MQTT payloads: observations and the device model as JSON (nlohmann-json).
#include "opencnc/connect/json_messages.hpp"

#include <fmt/format.h>

#include <ctime>
#include <nlohmann/json.hpp>

namespace opencnc::connect {

using nlohmann::json;

std::string iso_time(std::int64_t us) {
  const std::time_t seconds = static_cast<std::time_t>(us >= 0 ? us / 1000000 : (us - 999999) / 1000000);
  const auto micro = static_cast<int>(us - static_cast<std::int64_t>(seconds) * 1000000);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}.{:06}Z", tm.tm_year + 1900, tm.tm_mon + 1,
                     tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, micro);
}

namespace {

json observation(const DeviceModel& model, const Observation& o) {
  const DataItem& item = model.items()[o.item];
  json j{{"sequence", o.sequence},
         {"timestamp", iso_time(o.time_us)},
         {"dataItemId", item.id},
         {"component", model.components()[static_cast<std::size_t>(item.component)].id},
         {"category", to_string(item.category)},
         {"type", item.type}};
  if (!item.sub_type.empty()) j["subType"] = item.sub_type;
  if (item.category == Category::Condition) {
    j["level"] = to_string(o.level);
    if (!o.native_code.empty()) j["nativeCode"] = o.native_code;
    if (!o.value.empty()) j["message"] = o.value;
  } else {
    j["value"] = o.value;
  }
  return j;
}

json header(const DeviceModel& model, const AgentOptions& options) {
  return json{{"device", model.name()},
              {"uuid", model.uuid()},
              {"sender", options.sender},
              {"instanceId", options.instance_id}};
}

}  // namespace

std::string probe_json(const DeviceModel& model, const AgentOptions& options, std::string_view hmi_url) {
  json j = header(model, options);
  json components = json::array();
  for (const auto& c : model.components()) {
    json e{{"element", c.element}, {"id", c.id}};
    if (!c.name.empty()) e["name"] = c.name;
    if (c.parent >= 0) e["parent"] = model.components()[static_cast<std::size_t>(c.parent)].id;
    components.push_back(std::move(e));
  }
  json items = json::array();
  for (const auto& i : model.items()) {
    json e{{"id", i.id},
           {"category", to_string(i.category)},
           {"type", i.type},
           {"component", model.components()[static_cast<std::size_t>(i.component)].id}};
    if (!i.sub_type.empty()) e["subType"] = i.sub_type;
    if (!i.units.empty()) e["units"] = i.units;
    items.push_back(std::move(e));
  }
  j["description"] = model.description();
  if (!hmi_url.empty()) j["hmi"] = hmi_url;
  j["components"] = std::move(components);
  j["dataItems"] = std::move(items);
  return j.dump();
}

std::string sample_json(const DeviceModel& model, const AgentOptions& options,
                        std::span<const Observation> batch, const Gap& gap, std::uint64_t dropped_total) {
  json j = header(model, options);
  j["firstSequence"] = batch.empty() ? 0 : batch.front().sequence;
  j["lastSequence"] = batch.empty() ? 0 : batch.back().sequence;
  j["droppedTotal"] = dropped_total;
  if (gap.count > 0) j["gap"] = json{{"from", gap.from}, {"to", gap.to}, {"count", gap.count}};
  json list = json::array();
  for (const auto& o : batch) list.push_back(observation(model, o));
  j["observations"] = std::move(list);
  return j.dump();
}

std::string current_json(const DeviceModel& model, const AgentOptions& options,
                         std::span<const Observation> snapshot, std::uint64_t next_sequence,
                         double progress) {
  json j = header(model, options);
  j["nextSequence"] = next_sequence;
  j["progress"] = progress;
  json list = json::array();
  for (const auto& o : snapshot) list.push_back(observation(model, o));
  j["observations"] = std::move(list);
  return j.dump();
}

}  // namespace opencnc::connect
