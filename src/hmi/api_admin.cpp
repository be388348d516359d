// SPDX-License-Identifier: GPL-3.0-or-later
// The admin's part of the JSON API: the machine parameters as JSON and a change of them as the
// controller's EditProfile request (every range check is the profile loader's, in the controller).
#include "opencnc/hmi/api_admin.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <variant>

#include "opencnc/config/profile_edit.hpp"
#include "opencnc/config/toml_edit.hpp"
#include "opencnc/edm/sequence.hpp"

namespace opencnc::hmi {

using nlohmann::json;

ParametersRequest parameters_request(const json& body, const config::MachineProfile& profile) {
  ParametersRequest r;
  const auto values = body.find("values");
  if (values == body.end()) {
    r.message = "\"values\" is missing";
    return r;
  }
  if (!values->is_object() || values->empty()) {
    r.message = "\"values\" must be an object of parameter keys and numbers, with at least one";
    return r;
  }
  const std::vector<config::EditableParameter> editable = config::editable_parameters(profile);
  std::vector<config::ProfileKeyEdit> edits;
  for (const auto& [key, value] : values->items()) {
    const bool known = std::any_of(editable.begin(), editable.end(),
                                   [&](const config::EditableParameter& p) { return p.key == key; });
    if (!known) {
      r.status = 422;
      r.message = fmt::format(
          "\"{}\" is not a parameter that can be changed here (GET /api/v1/parameters lists them)", key);
      return r;
    }
    if (!value.is_number()) {
      r.message = fmt::format("\"{}\" must be a number", key);
      return r;
    }
    const double v = value.get<double>();
    if (!std::isfinite(v)) {
      r.status = 422;
      r.message = fmt::format("\"{}\" must be finite", key);
      return r;
    }
    edits.push_back({key, config::toml_number(v)});
  }
  r.request = controller::Request::edit_profile(std::move(edits));
  return r;
}

json parameters_json(const config::MachineProfile& profile) {
  json list = json::array();
  for (const config::EditableParameter& p : config::editable_parameters(profile))
    list.push_back({{"key", p.key}, {"value", p.value}, {"unit", p.unit}, {"what", p.what}});
  return {{"profile", profile.source},
          {"when", "while nothing runs (no program, MDI line, jog or homing)"},
          {"parameters", list}};
}

namespace {

/// `body[key]` as a TOML array of 1 … 256 finite numbers; "" with `r` filled when it is not.
std::string table_toml(const json& body, const char* key, ParametersRequest& r) {
  const auto v = body.find(key);
  if (v == body.end() || !v->is_array()) {
    r.message = fmt::format("\"{}\" must be an array of numbers (the errors at the table's points)", key);
    return {};
  }
  if (v->empty() || v->size() > static_cast<std::size_t>(config::kMaxCompensationPoints)) {
    r.status = 422;
    r.message = fmt::format("\"{}\" has {} points: a table has 1 to {}", key, v->size(),
                            config::kMaxCompensationPoints);
    return {};
  }
  std::string out = "[";
  for (const json& e : *v) {
    if (!e.is_number() || !std::isfinite(e.get<double>())) {
      r.status = e.is_number() ? 422 : 400;
      r.message = fmt::format("\"{}\" must hold finite numbers only", key);
      return {};
    }
    out += (out.size() > 1 ? ", " : "") + config::toml_number(e.get<double>());
  }
  return out + "]";
}

}  // namespace

ParametersRequest compensation_request(const json& body, const config::MachineProfile& profile) {
  ParametersRequest r;
  const auto axis = body.find("axis");
  if (axis == body.end() || !axis->is_string() || axis->get<std::string>().size() != 1) {
    r.message = "\"axis\" must be an axis letter";
    return r;
  }
  const char name = static_cast<char>(std::toupper(static_cast<unsigned char>(axis->get<std::string>()[0])));
  const config::AxisProfile* a = nullptr;
  for (const config::AxisProfile& p : profile.axes)
    if (letter(p.axis) == name) a = &p;
  if (!a || !a->compensation.present) {
    r.status = 422;
    r.message =
        fmt::format("axis {} has no compensation (GET /api/v1/compensation lists the axes that have)", name);
    return r;
  }
  const bool comp_file = !a->compensation.comp_file.empty();
  const std::string base = fmt::format("axis.{}.compensation.", static_cast<char>(std::tolower(name)));
  std::vector<config::ProfileKeyEdit> edits;
  const std::string forward = table_toml(body, "forward", r);
  if (forward.empty()) return r;
  const std::string reverse = table_toml(body, "reverse", r);
  if (reverse.empty()) return r;
  for (const char* key : {"start", "interval", "backlash"}) {
    const auto v = body.find(key);
    if (v == body.end()) continue;
    if (comp_file && key[0] != 'b') {
      r.status = 422;
      r.message = fmt::format(
          "axis {}'s table is in the comp file {}, which lists each point's position: send \"positions\", "
          "not "
          "\"{}\"",
          name, a->compensation.comp_file, key);
      return r;
    }
    if (!v->is_number() || !std::isfinite(v->get<double>())) {
      r.status = v->is_number() ? 422 : 400;
      r.message = fmt::format("\"{}\" must be a finite number", key);
      return r;
    }
    edits.push_back({base + key, config::toml_number(v->get<double>())});
  }
  if (body.contains("positions")) {
    if (!comp_file) {
      r.status = 422;
      r.message = fmt::format(
          "axis {}'s table has its points at start + k·interval: send \"start\" and \"interval\"", name);
      return r;
    }
    const std::string positions = table_toml(body, "positions", r);
    if (positions.empty()) return r;
    edits.push_back({base + "positions", positions});
  }
  edits.push_back({base + "forward", forward});
  edits.push_back({base + "reverse", reverse});
  r.request = controller::Request::edit_profile(std::move(edits));
  return r;
}

json compensation_json(const config::MachineProfile& profile) {
  json axes = json::array();
  for (const config::AxisProfile& a : profile.axes) {
    const config::CompensationProfile& c = a.compensation;
    if (!c.present) continue;
    json table = nullptr;
    if (!c.positions.empty())
      table = {{"positions", c.positions},
               {"forward", c.forward},
               {"reverse", c.reverse},
               {"one_table", c.one_table}};
    axes.push_back({{"axis", std::string(1, letter(a.axis))},
                    {"unit", a.rotary ? "deg" : "mm"},
                    {"backlash", c.backlash},
                    {"takeup_velocity", c.takeup_velocity},
                    {"takeup_acceleration", c.takeup_acceleration},
                    {"table", table},
                    {"comp_file", c.comp_file.empty() ? json(nullptr) : json(c.comp_file)},
                    {"comp_file_type", c.comp_file_type},
                    {"editable", true},
                    {"max_points", config::kMaxCompensationPoints}});
  }
  return {{"profile", profile.source},
          {"when", "while nothing runs (no program, MDI line, jog or homing)"},
          {"axes", axes}};
}

namespace {

/// "+|-" → ["+", "-"].
json words(std::string_view choices) {
  json out = json::array();
  while (!choices.empty()) {
    const std::size_t bar = choices.find('|');
    out.push_back(std::string(choices.substr(0, bar)));
    choices.remove_prefix(bar == std::string_view::npos ? choices.size() : bar + 1);
  }
  return out;
}

/// A request's integer as a condition's number (1–99); 0 for any other (not narrowed: 2^32 + 4 is
/// not condition 4).
int condition_number(const json& v) {
  const std::int64_t n = v.is_number_integer() ? v.get<std::int64_t>() : 0;
  return n >= 1 && n <= 99 ? static_cast<int>(n) : 0;
}

/// A condition field's value from the request as TOML text ("60.0", "\"-\""); "" with `r` filled
/// when the field cannot be changed or the value does not fit it.
std::string condition_value_toml(const std::string& key, const json& value, ParametersRequest& r) {
  const auto fields = config::condition_fields();
  const auto f = std::find_if(fields.begin(), fields.end(),
                              [&](const config::ConditionField& c) { return key == c.key; });
  if (f == fields.end()) {
    r.status = 422;
    r.message = fmt::format("\"{}\" is not a field of a condition that can be changed here", key);
    return {};
  }
  if (f->choices == nullptr) {
    if (!value.is_number()) {
      r.message = fmt::format("\"{}\" must be a number", key);
      return {};
    }
    if (!std::isfinite(value.get<double>())) {
      r.status = 422;
      r.message = fmt::format("\"{}\" must be finite", key);
      return {};
    }
    return config::toml_number(value.get<double>());
  }
  const json choices = words(f->choices);
  if (!value.is_string()) {
    r.message = fmt::format("\"{}\" must be one of {}", key, choices.dump());
    return {};
  }
  if (std::find(choices.begin(), choices.end(), value) == choices.end()) {
    r.status = 422;
    r.message = fmt::format("\"{}\" must be one of {}", key, choices.dump());
    return {};
  }
  if (std::string_view(f->choices) == "true|false") return value.get<std::string>();  // a TOML boolean
  return json(value).dump();  // a TOML basic string is a JSON string of these words
}

}  // namespace

json conditions_json(const config::MachineProfile& profile) {
  json list = json::array();
  const machine::EdmConfig& edm = profile.edm.config;
  for (int k = 0; profile.edm.present && k < edm.condition_count; ++k) {
    const machine::EdmCondition& c = edm.conditions[static_cast<std::size_t>(k)];
    json condition = {{"number", c.number}};
    for (const config::ConditionField& f : config::condition_fields()) {
      if (f.choices != nullptr)
        condition[f.key] = config::condition_field_text(c, f.key);
      else
        condition[f.key] = *config::condition_field_number(c, f.key);
    }
    list.push_back(std::move(condition));
  }
  json fields = json::array();
  for (const config::ConditionField& f : config::condition_fields()) {
    json field = {{"key", f.key}, {"unit", f.unit}, {"what", f.what}};
    if (f.choices != nullptr) field["choices"] = words(f.choices);
    fields.push_back(std::move(field));
  }
  return {{"profile", profile.source},
          {"when", "while nothing runs (no program, MDI line, jog or homing)"},
          {"fields", fields},
          {"conditions", list}};
}

std::pair<int, json> edm_sequence_json(const config::MachineProfile& profile,
                                       const std::map<std::string, std::string>& query) {
  auto refuse = [](int status, std::string message) {
    return std::pair<int, json>{status, json{{"message", std::move(message)}}};
  };
  if (!profile.edm.present) return refuse(422, "this machine is not a sinker EDM (no [edm] in its profile)");
  // A query value as a finite number; nullopt (and `why`) when absent or malformed.
  std::string why;
  auto number = [&](const char* key, bool required) -> std::optional<double> {
    const auto it = query.find(key);
    if (it == query.end() || it->second.empty()) {
      if (required) why = fmt::format("\"{}\" is needed", key);
      return std::nullopt;
    }
    double v = 0;
    const char* b = it->second.data();
    const auto [end, ec] = std::from_chars(b, b + it->second.size(), v);
    if (ec != std::errc{} || end != b + it->second.size() || !std::isfinite(v)) {
      why = fmt::format("\"{}\" must be a number, not \"{}\"", key, it->second);
      return std::nullopt;
    }
    return v;
  };
  const std::optional<double> area = number("area", true);
  const std::optional<double> undersize = number("undersize", true);
  const std::optional<double> surface = number("surface", false);
  const std::optional<double> depth = number("depth", false);
  if (!why.empty() || !area || !undersize) return refuse(400, why);
  const auto finish_it = query.find("finish");
  if (finish_it == query.end() || finish_it->second.empty()) return refuse(400, "\"finish\" is needed");
  const std::variant<double, std::string> finish = edm::parse_finish(finish_it->second);
  if (const auto* w = std::get_if<std::string>(&finish)) return refuse(400, *w);
  const std::variant<edm::Sequence, std::string> planned =
      edm::plan_sequence(profile.edm.config, {*area, std::get<double>(finish), *undersize});
  if (const auto* w = std::get_if<std::string>(&planned)) return refuse(422, *w);
  const edm::Sequence& s = std::get<edm::Sequence>(planned);
  json steps = json::array();
  for (const edm::SequenceStep& st : s.steps)
    steps.push_back({{"condition", st.condition},
                     {"peak_current_a", st.peak_current_a},
                     {"ra_um", st.ra_um},
                     {"vdi", edm::ra_to_vdi(st.ra_um)},
                     {"side_gap_mm", st.side_gap_mm},
                     {"orbit_mm", st.orbit_mm},
                     {"wall_mm", st.wall_mm},
                     {"allowance_mm", st.allowance_mm},
                     {"removal_mm3_min", st.removal_mm3_min},
                     {"wear_ratio", st.wear_ratio},
                     {"orbit_limited", st.orbit_limited}});
  json out = {{"finish_ra_um", s.request.finish_ra_um},
              {"vdi", edm::ra_to_vdi(s.request.finish_ra_um)},
              {"steps", steps},
              {"text", edm::sequence_text(s)}};
  if (depth) {
    if (!(*depth > 0)) return refuse(400, "\"depth\" must be above 0 mm");
    const machine::EdmConfig& e = profile.edm.config;
    const char letter = "XYZABCUVW"[static_cast<std::size_t>(e.tool_axis)];
    out["program"] = edm::sequence_program(s, e, letter, surface.value_or(0), *depth, e.lift_direction);
  }
  return {200, out};
}

ParametersRequest conditions_request(const json& body, const config::MachineProfile& profile) {
  ParametersRequest r;
  const auto number = body.find("condition");
  if (number == body.end() || !number->is_number_integer()) {
    r.message = "\"condition\" must be a condition's number";
    return r;
  }
  const int n = condition_number(*number);
  if (!profile.edm.present || profile.edm.config.find(n) == nullptr) {
    r.status = 422;
    r.message =
        fmt::format("the machine has no machining condition {} (GET /api/v1/conditions lists them)", n);
    return r;
  }
  const auto values = body.find("values");
  if (values == body.end() || !values->is_object() || values->empty()) {
    r.message = "\"values\" must be an object of a condition's fields and their values, with at least one";
    return r;
  }
  std::vector<config::ProfileKeyEdit> edits;
  for (const auto& [key, value] : values->items()) {
    const std::string toml = condition_value_toml(key, value, r);
    if (toml.empty()) return r;
    edits.push_back({fmt::format("edm.condition.{}.{}", n, key), toml});
  }
  r.request = controller::Request::edit_profile(std::move(edits));
  return r;
}

ParametersRequest condition_change_request(const json& body, const config::MachineProfile& profile, bool remove) {
  ParametersRequest r;
  const auto number = body.find("condition");
  if (number == body.end() || !number->is_number_integer()) {
    r.message = "\"condition\" must be a condition's number";
    return r;
  }
  const auto from = body.find("from");
  if (!remove && from != body.end() && !from->is_number_integer()) {
    r.message = "\"from\" must be the number of the condition to copy";
    return r;
  }
  r.status = 422;
  const machine::EdmConfig& edm = profile.edm.config;
  if (!profile.edm.present) {
    r.message = "this machine has no machining conditions (no [edm] section)";
    return r;
  }
  const int n = condition_number(*number);
  config::ConditionChange change{n, remove, 0};
  if (n == 0) {
    r.message = fmt::format("a machining condition's number is 1 to 99, not {}", number->dump());
    return r;
  }
  if (remove && edm.find(n) == nullptr) {
    r.message = fmt::format("the machine has no machining condition {} (GET /api/v1/conditions lists them)", n);
    return r;
  }
  if (!remove) {
    if (edm.find(n) != nullptr) {
      r.message = fmt::format("condition {} exists already: change its values with set-conditions", n);
      return r;
    }
    change.from = from != body.end() ? condition_number(*from) : config::condition_to_copy(edm, n);
    if (edm.find(change.from) == nullptr) {
      r.message = fmt::format("the machine has no machining condition {} to copy",
                              from != body.end() ? from->dump() : std::to_string(change.from));
      return r;
    }
  }
  r.request = controller::Request::change_conditions({change});
  return r;
}

}  // namespace opencnc::hmi
