// SPDX-License-Identifier: GPL-3.0-or-later
// The admin's part of the JSON API: the machine parameters as JSON and a change of them as the
// controller's EditProfile request (every range check is the profile loader's, in the controller).
#include "opencnc/hmi/api_admin.hpp"

#include <fmt/format.h>

#include <cmath>

#include "opencnc/config/profile_edit.hpp"
#include "opencnc/config/toml_edit.hpp"

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
  r.request = control::Request::edit_profile(std::move(edits));
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

}  // namespace opencnc::hmi
