// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart's calls: the chart as JSON, and a selection or an admin's change in one audited
// transaction of the store.
#include "opencnc/hmi/api_cutchart.hpp"

#include <cmath>

#include <fmt/format.h>

#include "opencnc/config/cut_chart_profile.hpp"
#include "opencnc/hmi/store_json.hpp"
#include "opencnc/store/cut_chart_store.hpp"

namespace opencnc::hmi {

namespace {

using nlohmann::json;

constexpr const char* kInterface = "hmi";

CutChartAnswer error(int status, std::string message) {
  return {status, json{{"error", std::move(message)}}};
}

struct Opened {
  std::shared_ptr<store::CutChartStore> store;
  std::optional<CutChartAnswer> refused;
};

Opened open(const config::MachineProfile& profile, bool writes) {
  Diagnostics d;
  const auto c = config::cut_chart_profile(profile, d);
  if (!c) return {nullptr, error(404, "this machine has no cut chart (a [cut_chart] in its profile)")};
  std::string why;
  auto s = store::CutChartStore::open(c->store, &why, false, !writes);
  if (!s) return {nullptr, error(500, why)};
  return {s, std::nullopt};
}

CutChartAnswer chart_json(store::CutChartStore& s) {
  std::string why;
  const auto chart = s.chart(&why);
  if (!chart) return error(500, why);
  json materials = json::array(), fields = json::array(), audit = json::array();
  for (const store::Material& m : *chart) materials.push_back(material_json(m));
  for (const store::MaterialField& f : store::material_fields())
    fields.push_back({{"name", f.name}, {"required", f.required}});
  for (const store::AuditEntry& e : s.audit(20)) audit.push_back(audit_json(e));
  return {200, json{{"store", s.path()},
                    {"selected", s.selected().value_or(0)},
                    {"fields", fields},
                    {"materials", materials},
                    {"audit", audit}}};
}

// A material's number in `v`: a whole number from 1 to 99999 (0 too when `none`).
std::optional<int> number_in(const json& v, bool none) {
  if (!v.is_number()) return std::nullopt;
  const double n = v.get<double>();
  if (!std::isfinite(n) || n != std::floor(n) || n < (none ? 0 : 1) || n > 99999) return std::nullopt;
  return static_cast<int>(n);
}

// The material an admin sends: every field given (as a number or, for name and process, a word).
std::variant<store::Material, CutChartAnswer> material_from(const json& j) {
  if (!j.is_object()) return error(400, "\"material\" must be an object of the material's fields");
  store::Material m;
  for (const store::MaterialField& f : store::material_fields()) {
    const auto it = j.find(f.name);
    if (it == j.end()) {
      if (f.required) return error(422, fmt::format("{}: missing", f.name));
      continue;
    }
    const std::string_view name = f.name;
    const bool word = name == "name" || name == "process";
    if (word != it->is_string() || (!word && !it->is_number()))
      return error(400, fmt::format("{}: {} expected", f.name, word ? "a string" : "a number"));
    const std::string text = word ? it->get<std::string>() : fmt::format("{}", it->get<double>());
    if (const auto why = store::set_field(m, name, text))
      return error(422, fmt::format("{}: {}", f.name, *why));
  }
  for (const auto& [key, value] : j.items()) {
    bool known = false;
    for (const store::MaterialField& f : store::material_fields()) known = known || key == f.name;
    if (!known) return error(422, fmt::format("{}: not a field of a material", key));
  }
  if (const auto bad = store::invalid(m)) return error(422, fmt::format("{}: {}", bad->field, bad->message));
  return m;
}

}  // namespace

CutChartAnswer cut_chart_get(const config::MachineProfile& profile) {
  Opened o = open(profile, false);
  if (o.refused) return *o.refused;
  return chart_json(*o.store);
}

CutChartAnswer cut_chart_post(const config::MachineProfile& profile, const json& body, Role role) {
  if (!body.is_object() || !body.contains("action") || !body["action"].is_string())
    return error(400, "a cut chart change is {\"action\": \"select\"|\"set\"|\"remove\", \"material\": …}");
  const std::string action = body["action"].get<std::string>();
  if (action != "select" && action != "set" && action != "remove")
    return error(400, fmt::format("unknown action \"{}\" (select, set, remove)", action));
  if (action != "select" && role != Role::Admin)
    return error(403, fmt::format("only an admin's token may {} a cut chart material", action));
  if (!body.contains("material")) return error(400, "\"material\" is missing");
  Opened o = open(profile, true);
  if (o.refused) return *o.refused;
  std::string why;
  bool ok = false;
  if (action == "set") {
    auto m = material_from(body["material"]);
    if (auto* refused = std::get_if<CutChartAnswer>(&m)) return *refused;
    ok = o.store->put(std::get<store::Material>(m), kInterface, &why);
  } else {
    const auto n = number_in(body["material"], action == "select");
    if (!n)
      return error(422, fmt::format("\"material\" must be a material's number (1 to 99999{})",
                                    action == "select" ? "; 0: none" : ""));
    ok = action == "select" ? o.store->select(*n, kInterface, &why) : o.store->remove(*n, kInterface, &why);
  }
  if (!ok) return error(422, why);
  return chart_json(*o.store);
}

}  // namespace opencnc::hmi
