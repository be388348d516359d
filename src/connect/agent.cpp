// SPDX-License-Identifier: GPL-3.0-or-later
// The MTConnect agent: sampling the status into observations, and the probe, streams, assets and
// error documents (MTConnect 2.7, validated against its schemas in tests/connect).
#include "opencnc/connect/agent.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/connect/json_messages.hpp"
#include "path_filter.hpp"
#include "xml_writer.hpp"

namespace opencnc::connect {

namespace {

constexpr const char* kVersion = "2.7.0.0";
constexpr const char* kStreamsNs = "urn:mtconnect.org:MTConnectStreams:2.7";
constexpr const char* kDevicesNs = "urn:mtconnect.org:MTConnectDevices:2.7";
constexpr const char* kAssetsNs = "urn:mtconnect.org:MTConnectAssets:2.7";
constexpr const char* kErrorNs = "urn:mtconnect.org:MTConnectError:2.7";
constexpr std::size_t kAssetBufferSize = 1024;

/// Opens a document's Header with the attributes every MTConnect document has; the caller adds its
/// own (bufferSize, sequences, asset counts) and closes it.
void start_header(XmlWriter& w, const AgentOptions& options, std::int64_t now_us) {
  w.start("Header");
  w.attribute("creationTime", iso_time(now_us));
  w.attribute("sender", options.sender);
  w.attribute("instanceId", fmt::format("{}", options.instance_id));
  w.attribute("version", kVersion);
  w.attribute("deviceModelChangeTime", iso_time(0));
}

int hex(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string decode(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '+') {
      out += ' ';
    } else if (s[i] == '%' && i + 2 < s.size() && hex(s[i + 1]) >= 0 && hex(s[i + 2]) >= 0) {
      out += static_cast<char>(hex(s[i + 1]) * 16 + hex(s[i + 2]));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

/// A query parameter as an unsigned integer; nullopt when absent, error text when malformed.
struct Number {
  bool present = false;
  bool ok = true;
  std::uint64_t value = 0;
};
Number number(const AgentRequest& r, std::string_view name) {
  Number n;
  auto it = r.query.find(name);
  if (it == r.query.end()) return n;
  n.present = true;
  const std::string& s = it->second;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), n.value);
  n.ok = ec == std::errc{} && p == s.data() + s.size() && !s.empty();
  return n;
}

}  // namespace

AgentRequest parse_agent_request(std::string_view target) {
  AgentRequest r;
  const auto q = target.find('?');
  r.path = decode(target.substr(0, q));
  if (q == std::string_view::npos) return r;
  std::string_view rest = target.substr(q + 1);
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const std::string_view pair = rest.substr(0, amp);
    const auto eq = pair.find('=');
    if (!pair.empty())
      r.query[decode(pair.substr(0, eq))] =
          eq == std::string_view::npos ? std::string() : decode(pair.substr(eq + 1));
    rest = amp == std::string_view::npos ? std::string_view() : rest.substr(amp + 1);
  }
  return r;
}

Agent::Agent(DeviceModel model, std::vector<std::unique_ptr<Contribution>> contributions,
             AgentOptions options)
    : model_(std::move(model)),
      contributions_(std::move(contributions)),
      options_(std::move(options)),
      buffer_(0, 1) {
  availability_ =
      model_.add_item(DataItem{"avail", Category::Event, "AVAILABILITY", {}, {}, "Availability", 0});
  asset_changed_ =
      model_.add_item(DataItem{"asset_chg", Category::Event, "ASSET_CHANGED", {}, {}, "AssetChanged", 0});
  asset_removed_ =
      model_.add_item(DataItem{"asset_rem", Category::Event, "ASSET_REMOVED", {}, {}, "AssetRemoved", 0});
  for (auto& c : contributions_) c->describe(model_);
  buffer_ = ObservationBuffer(model_.items().size(), options_.buffer_size);
  for (std::size_t i = 0; i < model_.items().size(); ++i)
    add(i, Level::Unavailable, {}, model_.items()[i].category == Category::Condition ? "" : "UNAVAILABLE",
        options_.start_us);
}

std::unique_ptr<Agent> Agent::for_profile(const config::MachineProfile& profile, AgentOptions options) {
  const std::string name = !options.device_name.empty() ? options.device_name
                           : profile.name.empty()       ? std::string("opencnc")
                                                        : profile.name;
  DeviceModel model(name, "opencnc-" + xml_id(name),
                    profile.description.empty() ? std::string("opencnc machine") : profile.description);
  return std::make_unique<Agent>(std::move(model), contributions_for(profile), std::move(options));
}

void Agent::add(std::size_t item, Level level, std::string native_code, std::string value,
                std::int64_t time_us) {
  Observation o;
  o.time_us = time_us;
  o.item = static_cast<std::uint32_t>(item);
  o.level = level;
  o.native_code = std::move(native_code);
  o.value = std::move(value);
  buffer_.add(std::move(o));
}

void Agent::observe(const controller::ControllerStatus& status, std::int64_t time_us) {
  ValueSink sink(model_.items().size());
  for (const auto& c : contributions_) c->observe(status, sink);
  std::lock_guard lock(mutex_);
  progress_ = status.progress;
  if (!observed_) {
    observed_ = true;
    add(availability_, Level::Unavailable, {}, "AVAILABLE", time_us);
  }
  const auto& now = buffer_.current();
  const auto& items = model_.items();
  for (std::size_t i = 0; i < items.size(); ++i) {
    const auto& slot = sink.slots()[i];
    if (items[i].category != Category::Condition) {
      if (slot.set && now[i].last.value != slot.value) add(i, Level::Unavailable, {}, slot.value, time_us);
      continue;
    }
    // Conditions: each one that appeared or changed, each one that went, and Normal when the item
    // had never been observed (it starts UNAVAILABLE).
    const auto state = now[i];  // copy: add() changes it
    for (const auto& c : slot.conditions) {
      auto same = std::find_if(state.active.begin(), state.active.end(),
                               [&](const Observation& a) { return a.native_code == c.native_code; });
      if (same == state.active.end() || same->level != c.level || same->value != c.value)
        add(i, c.level, c.native_code, c.value, time_us);
    }
    for (const auto& a : state.active) {
      const bool stays = std::any_of(slot.conditions.begin(), slot.conditions.end(),
                                     [&](const Observation& c) { return c.native_code == a.native_code; });
      if (!stays) add(i, Level::Normal, a.native_code, {}, time_us);
    }
    if (slot.conditions.empty() && state.active.empty() && state.last.level == Level::Unavailable)
      add(i, Level::Normal, {}, {}, time_us);
  }
}

void Agent::mark_unavailable(std::int64_t time_us) {
  std::lock_guard lock(mutex_);
  const auto& items = model_.items();
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i == asset_changed_ || i == asset_removed_) continue;
    const auto& s = buffer_.current()[i];
    if (items[i].category == Category::Condition) {
      if (s.last.level != Level::Unavailable || !s.active.empty())
        add(i, Level::Unavailable, {}, {}, time_us);
    } else if (s.last.value != "UNAVAILABLE") {
      add(i, Level::Unavailable, {}, "UNAVAILABLE", time_us);
    }
  }
  observed_ = false;
}

void Agent::set_tools(std::vector<ToolAsset> tools, std::int64_t time_us) {
  std::sort(tools.begin(), tools.end(),
            [](const ToolAsset& a, const ToolAsset& b) { return a.number < b.number; });
  std::lock_guard lock(mutex_);
  auto find = [](const std::vector<ToolAsset>& list, int number) -> const ToolAsset* {
    for (const auto& t : list)
      if (t.number == number) return &t;
    return nullptr;
  };
  for (const auto& t : tools) {
    const ToolAsset* before = find(tools_, t.number);
    if (before == nullptr || before->pocket != t.pocket || before->length_mm != t.length_mm ||
        before->diameter_mm != t.diameter_mm || before->comment != t.comment)
      add(asset_changed_, Level::Unavailable, {}, fmt::format("T{}", t.number), time_us);
  }
  for (const auto& t : tools_)
    if (find(tools, t.number) == nullptr)
      add(asset_removed_, Level::Unavailable, {}, fmt::format("T{}", t.number), time_us);
  tools_ = std::move(tools);
}

std::uint64_t Agent::next_sequence() const {
  std::lock_guard lock(mutex_);
  return buffer_.next_sequence();
}

double Agent::progress() const {
  std::lock_guard lock(mutex_);
  return progress_;
}

std::uint64_t Agent::first_sequence() const {
  std::lock_guard lock(mutex_);
  return buffer_.first_sequence();
}

std::vector<Observation> Agent::observations(std::uint64_t from, std::size_t max,
                                             std::uint64_t* first) const {
  std::lock_guard lock(mutex_);
  const std::uint64_t start = std::max(from, buffer_.first_sequence());
  if (first != nullptr) *first = start;
  std::vector<Observation> out;
  for (std::uint64_t s = start; s < buffer_.next_sequence() && out.size() < max; ++s)
    out.push_back(buffer_.at(s));
  return out;
}

std::vector<Observation> Agent::snapshot(std::uint64_t* next) const {
  std::lock_guard lock(mutex_);
  if (next != nullptr) *next = buffer_.next_sequence();
  std::vector<Observation> out;
  for (const auto& s : buffer_.current()) {
    if (!s.active.empty())
      out.insert(out.end(), s.active.begin(), s.active.end());
    else
      out.push_back(s.last);
  }
  return out;
}

// --- Requests ----------------------------------------------------------------------------------

AgentResponse Agent::respond(const AgentRequest& request, std::int64_t now_us) const {
  // "/probe" or "/<device>/probe"; "/" is the probe as well.
  std::string_view path = request.path;
  if (path.empty() || path == "/") return probe(request, now_us);
  std::string_view rest = path.substr(1);
  std::string_view call = rest;
  if (const auto slash = rest.find('/'); slash != std::string_view::npos) {
    const std::string_view device = rest.substr(0, slash);
    call = rest.substr(slash + 1);
    if (device != model_.name() && device != model_.uuid())
      return error("NO_DEVICE",
                   fmt::format("no device named '{}' here: this agent serves '{}'", device, model_.name()),
                   request, now_us);
  }
  if (call == "probe") return probe(request, now_us);
  if (call == "current") return current(request, now_us);
  if (call == "sample") return sample(request, now_us).response;
  if (call == "assets" || call == "asset") return assets(request, now_us);
  return error("INVALID_URI",
               fmt::format("'{}' is not a request this agent answers (probe, current, sample, assets)", path),
               request, now_us);
}

AgentResponse Agent::error(std::string_view code, std::string message, const AgentRequest& request,
                           std::int64_t now_us, std::string_view parameter) const {
  XmlWriter w;
  w.start("MTConnectError");
  w.attribute("xmlns", kErrorNs);
  start_header(w, options_, now_us);
  w.attribute("bufferSize", fmt::format("{}", options_.buffer_size));
  w.end();
  w.start("Errors");
  static constexpr std::pair<std::string_view, std::string_view> kElements[] = {
      {"NO_DEVICE", "NoDevice"},
      {"INVALID_URI", "InvalidURI"},
      {"OUT_OF_RANGE", "OutOfRange"},
      {"INVALID_XPATH", "InvalidXPath"},
      {"INVALID_REQUEST", "InvalidRequest"},
      {"ASSET_NOT_FOUND", "AssetNotFound"},
      {"INVALID_PARAMETER_VALUE", "InvalidParameterValue"},
  };
  // OutOfRange and InvalidParameterValue cite the parameter, and the schema knows only some by
  // name (not `at`): an error about another one is an InvalidRequest.
  static constexpr std::string_view kParameters[] = {"device", "deviceType", "path",     "from",
                                                     "count",  "interval",   "heartbeat"};
  const bool cites = code == "OUT_OF_RANGE" || code == "INVALID_PARAMETER_VALUE";
  if (cites && std::find(std::begin(kParameters), std::end(kParameters), parameter) == std::end(kParameters))
    code = "INVALID_REQUEST";
  std::string_view element = "InvalidRequest";
  for (const auto& [c, e] : kElements)
    if (c == code) element = e;
  w.start(element);
  if (code == "ASSET_NOT_FOUND") {
    w.start("AssetId");
    w.text(parameter);
    w.end();
  }
  if (!parameter.empty() && (code == "OUT_OF_RANGE" || code == "INVALID_PARAMETER_VALUE")) {
    w.start("QueryParameter");
    w.attribute("name", parameter);
    if (auto it = request.query.find(parameter); it != request.query.end()) {
      w.start("Value");
      w.text(it->second);
      w.end();
    }
    w.end();
  }
  w.start("URI");
  w.text(request.path);
  w.end();
  w.start("ErrorMessage");
  w.text(message);
  w.end();
  w.start("Request");
  const auto slash = request.path.rfind('/');
  w.text(slash == std::string::npos ? request.path : request.path.substr(slash + 1));
  w.end();
  w.end();
  AgentResponse r;
  r.status = code == "NO_DEVICE" || code == "INVALID_URI" || code == "ASSET_NOT_FOUND" ? 404 : 400;
  r.body = w.finish();
  return r;
}

AgentResponse Agent::probe(const AgentRequest&, std::int64_t now_us) const {
  XmlWriter w;
  w.start("MTConnectDevices");
  w.attribute("xmlns", kDevicesNs);
  start_header(w, options_, now_us);
  w.attribute("bufferSize", fmt::format("{}", options_.buffer_size));
  w.attribute("assetBufferSize", fmt::format("{}", kAssetBufferSize));
  {
    std::lock_guard lock(mutex_);
    w.attribute("assetCount", fmt::format("{}", tools_.size()));
  }
  w.end();
  w.start("Devices");
  const auto& comps = model_.components();
  const auto& items = model_.items();
  // Components nest as the model says; each writes its data items, then its children.
  auto write = [&](auto&& self, std::size_t c) -> void {
    w.start(comps[c].element);
    w.attribute("id", comps[c].id);
    if (!comps[c].name.empty()) w.attribute("name", comps[c].name);
    if (c == 0) {
      w.attribute("uuid", model_.uuid());
      w.start("Description");
      w.attribute("manufacturer", "opencnc");
      w.text(model_.description());
      w.end();
    }
    bool any = false;
    for (const auto& item : items) {
      if (static_cast<std::size_t>(item.component) != c) continue;
      if (!any) w.start("DataItems");
      any = true;
      w.start("DataItem");
      w.attribute("category", to_string(item.category));
      w.attribute("id", item.id);
      w.attribute("type", item.type);
      if (!item.sub_type.empty()) w.attribute("subType", item.sub_type);
      if (!item.units.empty()) w.attribute("units", item.units);
      w.end();
    }
    if (any) w.end();
    bool children = false;
    for (std::size_t k = 0; k < comps.size(); ++k) {
      if (comps[k].parent != static_cast<int>(c)) continue;
      if (!children) w.start("Components");
      children = true;
      self(self, k);
    }
    if (children) w.end();
    w.end();
  };
  write(write, 0);
  w.end();
  w.end();
  return AgentResponse{200, "text/xml; charset=utf-8", w.finish()};
}

namespace {

/// Writes an MTConnectStreams document of `observations` (one per item at most for /current, any
/// number for /sample), grouped by component in the model's order.
std::string streams_document(const DeviceModel& model, const AgentOptions& options, std::int64_t now_us,
                             std::uint64_t first, std::uint64_t last, std::uint64_t next,
                             const std::vector<const Observation*>& observations) {
  XmlWriter w;
  w.start("MTConnectStreams");
  w.attribute("xmlns", kStreamsNs);
  start_header(w, options, now_us);
  w.attribute("bufferSize", fmt::format("{}", options.buffer_size));
  w.attribute("firstSequence", fmt::format("{}", first));
  w.attribute("lastSequence", fmt::format("{}", last));
  w.attribute("nextSequence", fmt::format("{}", next));
  w.end();
  w.start("Streams");
  w.start("DeviceStream");
  w.attribute("name", model.name());
  w.attribute("uuid", model.uuid());
  const auto& comps = model.components();
  const auto& items = model.items();
  for (std::size_t c = 0; c < comps.size(); ++c) {
    bool opened = false;
    for (Category category : {Category::Sample, Category::Event, Category::Condition}) {
      bool group = false;
      for (const Observation* o : observations) {
        const DataItem& item = items[o->item];
        if (static_cast<std::size_t>(item.component) != c || item.category != category) continue;
        if (!opened) {
          w.start("ComponentStream");
          w.attribute("component", comps[c].element);
          w.attribute("componentId", comps[c].id);
          if (!comps[c].name.empty()) w.attribute("name", comps[c].name);
          opened = true;
        }
        if (!group)
          w.start(category == Category::Sample  ? "Samples"
                  : category == Category::Event ? "Events"
                                                : "Condition");
        group = true;
        w.start(category == Category::Condition ? std::string(to_string(o->level)) : item.element);
        w.attribute("dataItemId", item.id);
        if (category == Category::Condition) w.attribute("type", item.type);
        if (!item.sub_type.empty()) w.attribute("subType", item.sub_type);
        w.attribute("sequence", fmt::format("{}", o->sequence));
        w.attribute("timestamp", iso_time(o->time_us));
        if (category == Category::Condition) {
          // conditionId ties a Warning or Fault to its Normal; the schema allows it on those two only.
          const bool active = o->level == Level::Warning || o->level == Level::Fault;
          if (!o->native_code.empty()) w.attribute("nativeCode", o->native_code);
          if (active) w.attribute("conditionId", o->native_code.empty() ? item.id : o->native_code);
          if (!o->value.empty()) w.text(o->value);
        } else {
          if (item.type == "ASSET_CHANGED" || item.type == "ASSET_REMOVED")
            w.attribute("assetType", o->value == "UNAVAILABLE" ? "UNAVAILABLE" : "CuttingTool");
          w.text(o->value);
        }
        w.end();
      }
      if (group) w.end();
    }
    if (opened) w.end();
  }
  w.end();
  w.end();
  w.end();
  return w.finish();
}

}  // namespace

AgentResponse Agent::current(const AgentRequest& request, std::int64_t now_us) const {
  std::vector<bool> selected(model_.items().size(), true);
  if (auto it = request.query.find("path"); it != request.query.end()) {
    std::string why;
    auto s = select_items(model_, it->second, &why);
    if (!s) return error("INVALID_XPATH", why, request, now_us);
    selected = std::move(*s);
  }
  const Number at = number(request, "at");
  if (!at.ok)
    return error("INVALID_PARAMETER_VALUE", "'at' must be a sequence number", request, now_us, "at");
  if (request.query.count("interval") != 0U)
    return error("INVALID_REQUEST", "/current with an interval is streamed by the server, not answered here",
                 request, now_us);
  std::lock_guard lock(mutex_);
  std::vector<ItemState> state;
  const std::vector<ItemState>* view = &buffer_.current();
  std::uint64_t next = buffer_.next_sequence();
  if (at.present) {
    if (at.value < buffer_.first_sequence() || at.value >= buffer_.next_sequence())
      return error(
          "OUT_OF_RANGE",
          fmt::format("'at' must lie between {} and {}", buffer_.first_sequence(), buffer_.last_sequence()),
          request, now_us, "at");
    state = buffer_.state_at(at.value);
    view = &state;
    next = at.value + 1;
  }
  std::vector<const Observation*> list;
  std::vector<Observation> normal;  // conditions whose last one cleared: Normal as a whole
  normal.reserve(view->size());
  for (std::size_t i = 0; i < view->size(); ++i) {
    if (!selected[i]) continue;
    const ItemState& s = (*view)[i];
    if (s.last.sequence == 0) continue;  // `at` before the item's first observation
    if (!s.active.empty()) {
      for (const auto& a : s.active) list.push_back(&a);
    } else if (model_.items()[i].category == Category::Condition && s.last.level == Level::Normal &&
               !s.last.native_code.empty()) {
      // The last one of several cleared: the item is Normal as a whole.
      normal.push_back(s.last);
      normal.back().native_code.clear();
      list.push_back(&normal.back());
    } else {
      list.push_back(&s.last);
    }
  }
  return AgentResponse{200, "text/xml; charset=utf-8",
                       streams_document(model_, options_, now_us, buffer_.first_sequence(),
                                        buffer_.last_sequence(), next, list)};
}

SampleAnswer Agent::sample(const AgentRequest& request, std::int64_t now_us) const {
  SampleAnswer answer;
  std::vector<bool> selected(model_.items().size(), true);
  if (auto it = request.query.find("path"); it != request.query.end()) {
    std::string why;
    auto s = select_items(model_, it->second, &why);
    if (!s) {
      answer.response = error("INVALID_XPATH", why, request, now_us);
      return answer;
    }
    selected = std::move(*s);
  }
  const Number from = number(request, "from"), count = number(request, "count");
  for (const auto& [name, n] : {std::pair{"from", from}, std::pair{"count", count}}) {
    if (!n.ok) {
      answer.response = error("INVALID_PARAMETER_VALUE", fmt::format("'{}' must be a whole number ≥ 0", name),
                              request, now_us, name);
      return answer;
    }
  }
  const std::uint64_t wanted = count.present ? count.value : 100;
  if (wanted == 0 || wanted > options_.max_count) {
    answer.response =
        error("OUT_OF_RANGE", fmt::format("'count' must lie between 1 and {}", options_.max_count), request,
              now_us, "count");
    return answer;
  }
  std::lock_guard lock(mutex_);
  const std::uint64_t first = buffer_.first_sequence(), next = buffer_.next_sequence();
  const std::uint64_t start = from.present ? from.value : first;
  if (start < first || start > next) {
    answer.response = error("OUT_OF_RANGE", fmt::format("'from' must lie between {} and {}", first, next),
                            request, now_us, "from");
    return answer;
  }
  std::vector<const Observation*> list;
  std::uint64_t s = start;
  for (; s < next && list.size() < wanted; ++s) {
    const Observation& o = buffer_.at(s);
    if (selected[o.item]) list.push_back(&o);
  }
  answer.next_from = s;
  answer.empty = list.empty();
  answer.response =
      AgentResponse{200, "text/xml; charset=utf-8",
                    streams_document(model_, options_, now_us, first, buffer_.last_sequence(), s, list)};
  return answer;
}

AgentResponse Agent::assets(const AgentRequest& request, std::int64_t now_us) const {
  std::lock_guard lock(mutex_);
  XmlWriter w;
  w.start("MTConnectAssets");
  w.attribute("xmlns", kAssetsNs);
  start_header(w, options_, now_us);
  w.attribute("assetBufferSize", fmt::format("{}", kAssetBufferSize));
  w.attribute("assetCount", fmt::format("{}", tools_.size()));
  w.end();
  w.start("Assets");
  for (const auto& t : tools_) {
    w.start("CuttingTool");
    w.attribute("assetId", fmt::format("T{}", t.number));
    w.attribute("timestamp", iso_time(t.changed_us));
    w.attribute("deviceUuid", model_.uuid());
    w.attribute("serialNumber", fmt::format("{}", t.number));
    w.attribute("toolId", fmt::format("{}", t.number));
    w.start("CuttingToolLifeCycle");
    w.start("CutterStatus");
    w.start("Status");
    w.text("AVAILABLE");
    w.end();
    w.end();
    w.start("ProgramToolNumber");
    w.text(fmt::format("{}", t.number));
    w.end();
    if (t.pocket > 0) {
      w.start("Location");
      w.attribute("type", "POT");
      w.text(fmt::format("{}", t.pocket));
      w.end();
    }
    w.start("Measurements");
    w.start("FunctionalLength");
    w.attribute("units", "MILLIMETER");
    w.attribute("code", "LF");
    w.text(fmt::format("{:.4f}", t.length_mm));
    w.end();
    w.start("CuttingDiameterMax");
    w.attribute("units", "MILLIMETER");
    w.attribute("code", "DC");
    w.text(fmt::format("{:.4f}", t.diameter_mm));
    w.end();
    w.end();
    w.end();
    if (!t.comment.empty()) {
      w.start("Description");
      w.text(t.comment);
      w.end();
    }
    w.end();
  }
  w.end();
  w.end();
  (void)request;
  return AgentResponse{200, "text/xml; charset=utf-8", w.finish()};
}

// --- ValueSink -------------------------------------------------------------------------------

ValueSink::ValueSink(std::size_t items) : slots_(items) {}

void ValueSink::set(std::size_t item, std::string value) {
  slots_.at(item).set = true;
  slots_[item].value = std::move(value);
}

void ValueSink::set(std::size_t item, double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.starts_with('-') && text.find_first_not_of("-0.") == std::string::npos)
    text.erase(0, 1);  // no "-0.0000"
  set(item, std::move(text));
}

void ValueSink::condition(std::size_t item, Level level, std::string native_code, std::string text) {
  Observation o;
  o.item = static_cast<std::uint32_t>(item);
  o.level = level;
  o.native_code = std::move(native_code);
  o.value = std::move(text);
  slots_.at(item).conditions.push_back(std::move(o));
}

}  // namespace opencnc::connect
