// SPDX-License-Identifier: GPL-3.0-or-later
// The API's one command kind for the controller's features: `{"kind": "feature", "feature": F,
// "action": A, …}` checked field by field and turned into Request::feature(F, A, args) — the
// power-fail journal, retrace, electrode setting and the tool guard (docs/api.md, "Features").
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>

#include <fmt/format.h>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/edm/electrode_setting.hpp"
#include "opencnc/hmi/api.hpp"
#include "opencnc/retrace/retrace.hpp"

namespace opencnc::hmi {

namespace {

using controller::Request;
using nlohmann::json;

struct Refused {
  int status;
  std::string message;
};

/// An optional number within [lo, hi]: `fallback` when the body lacks it.
double number_or(const json& body, const char* name, double fallback, double lo, double hi) {
  const auto it = body.find(name);
  if (it == body.end()) return fallback;
  if (!it->is_number()) throw Refused{400, fmt::format("\"{}\" must be a number", name)};
  const double v = it->get<double>();
  if (!std::isfinite(v) || v < lo || v > hi)
    throw Refused{422, fmt::format("\"{}\" must be within {} … {}, not {}", name, lo, hi, v)};
  return v;
}

double required(const json& body, const char* name, double lo, double hi) {
  if (!body.contains(name)) throw Refused{400, fmt::format("\"{}\" is missing", name)};
  return number_or(body, name, 0, lo, hi);
}

std::string text_or(const json& body, const char* name, std::string fallback) {
  const auto it = body.find(name);
  if (it == body.end()) return fallback;
  if (!it->is_string()) throw Refused{400, fmt::format("\"{}\" must be a string", name)};
  return it->get<std::string>();
}

/// The choices that move the machine or change kept data need the operator's confirmation in
/// the body (the front end asks; the audit trail keeps the body).
void confirmed(const json& body, std::string_view what) {
  const auto it = body.find("confirmed");
  if (it == body.end() || !it->is_boolean() || !it->get<bool>())
    throw Refused{400, fmt::format("{} must be confirmed by the operator: add \"confirmed\": true", what)};
}

/// The fastest axis speed of the machine, mm/min (the bound of a speed field).
double fastest_mm_min(const config::MachineProfile& p) {
  double v = 0;
  for (const config::AxisProfile& a : p.axes) v = std::max(v, a.max_velocity * 60);
  return v;
}

Request journal(const std::string& action, const json& body, const config::MachineProfile& p) {
  if (action == "show") return Request::feature("journal", "show");
  if (action == "resume") {
    confirmed(body, "resume");
    recovery::ResumeArgs a;  // the profile's values unless the operator changed them
    a.tolerance_mm = number_or(body, "tolerance_mm", p.power.resume_tolerance_mm, 0, 1);
    a.tolerance_deg = number_or(body, "tolerance_deg", p.power.resume_tolerance_deg, 0, 1);
    a.run_in_mm = number_or(body, "run_in_mm", p.power.resume_run_in_mm, 0, 50);
    a.run_in_speed_mm_min =
        number_or(body, "run_in_speed_mm_min", p.power.resume_run_in_speed_mm_min, 1, fastest_mm_min(p));
    return Request::feature("journal", "resume", a);
  }
  if (action == "retract") {
    confirmed(body, "retract");
    recovery::RetractArgs a;
    a.distance_mm = required(body, "distance_mm", 0.001, 1000);
    const std::string dir = text_or(body, "direction", "back");
    if (dir != "back" && dir != "onward")
      throw Refused{400, fmt::format("\"direction\" must be back or onward, not \"{}\"", dir)};
    a.onward = dir == "onward";
    a.speed_mm_min = number_or(body, "speed_mm_min", a.speed_mm_min, 1, fastest_mm_min(p));
    return Request::feature("journal", "retract", a);
  }
  if (action == "discard") {
    confirmed(body, "discard");
    return Request::feature("journal", "discard");
  }
  throw Refused{400,
                fmt::format("the journal has no action \"{}\" (show, resume, retract, discard)", action)};
}

Request retrace(const std::string& action, const json& body) {
  if (action == "pause" || action == "index") return Request::feature("retrace", action);
  if (action == "start") {
    confirmed(body, "resuming the cut");
    recovery::RetraceStart a;
    const std::string metric = text_or(body, "metric", "xy");
    if (metric != "xy" && metric != "xyz")
      throw Refused{400, fmt::format("\"metric\" must be xy or xyz, not \"{}\"", metric)};
    a.metric = metric == "xy" ? recovery::Metric::Xy : recovery::Metric::Xyz;
    a.margin_mm = number_or(body, "margin_mm", a.margin_mm, 0, 1000);
    a.candidate = static_cast<std::size_t>(number_or(body, "candidate", 0, 0, 1000));
    if (body.contains("stop_at_a")) {
      if (!body["stop_at_a"].is_boolean()) throw Refused{400, "\"stop_at_a\" must be true or false"};
      a.stop_at_a = body["stop_at_a"].get<bool>();
    }
    return Request::feature("retrace", "start", a);
  }
  if (action == "step") {
    recovery::RetraceStep a;
    a.distance_mm = required(body, "distance_mm", -1e6, 1e6);
    if (a.distance_mm == 0) throw Refused{422, "\"distance_mm\" must not be 0"};
    return Request::feature("retrace", "step", a);
  }
  throw Refused{400, fmt::format("retrace has no action \"{}\" (pause, start, step, index)", action)};
}

Request electrode(const std::string& action, const json& body) {
  if (action == "measure") {
    const double t = required(body, "tool", 1, 99999);
    if (t != std::floor(t)) throw Refused{422, "\"tool\" must be a tool number from 1 to 99999"};
    // By default the offsets are shown first and stored by a confirmed "write".
    bool write = false;
    if (body.contains("write")) {
      if (!body["write"].is_boolean()) throw Refused{400, "\"write\" must be true or false"};
      write = body["write"].get<bool>();
    }
    if (write) confirmed(body, "storing the measured offsets");
    edm::ElectrodeMeasure m{static_cast<int>(t), write, std::nullopt};
    if (body.contains("b_deg")) m.b_deg = required(body, "b_deg", -100000, 100000);
    return Request::feature("electrode", "measure", m);
  }
  if (action == "calibrate-b") {
    const double t = required(body, "tool", 1, 99999);
    if (t != std::floor(t)) throw Refused{422, "\"tool\" must be a tool number from 1 to 99999"};
    const auto angles = body.find("angles_deg");
    if (angles == body.end() || !angles->is_array() || angles->size() < 3 || angles->size() > 64)
      throw Refused{400, "\"angles_deg\" must be a list of 3 to 64 B angles, degrees"};
    edm::BAxisCalibrate c{static_cast<int>(t), {}};
    for (const json& a : *angles) {
      if (!a.is_number() || !std::isfinite(a.get<double>()))
        throw Refused{400, "\"angles_deg\" must be a list of 3 to 64 B angles, degrees"};
      c.angles_deg.push_back(a.get<double>());
    }
    confirmed(body, "calibrating B's axis");  // B turns, and the axis found replaces the one in use
    return Request::feature("electrode", "calibrate-b", c);
  }
  if (action == "write") {
    confirmed(body, "storing the measured offsets");
    return Request::feature("electrode", "write");
  }
  if (action == "resume") {
    confirmed(body, "resuming the program");
    return Request::feature("electrode", "resume");
  }
  throw Refused{400,
                fmt::format("electrode has no action \"{}\" (measure, write, resume, calibrate-b)", action)};
}

Request tool_guard(const std::string& action, const json& body) {
  if (action == "check") return Request::feature("tool-guard", "check");
  if (action == "accept") {
    confirmed(body, "accepting the live tool values as the new backup");
    return Request::feature("tool-guard", "accept");
  }
  if (action == "restore") {
    confirmed(body, "restoring the backup's tool values");
    if (!body.contains("backup")) return Request::feature("tool-guard", "restore");
    const double id = required(body, "backup", 1, 9.0e15);
    if (id != std::floor(id)) throw Refused{422, "\"backup\" must be a backup's number"};
    return Request::feature("tool-guard", "restore", static_cast<std::int64_t>(id));
  }
  throw Refused{400, fmt::format("tool-guard has no action \"{}\" (check, accept, restore)", action)};
}

}  // namespace

std::variant<controller::Request, ApiError> parse_feature_command(const json& body,
                                                                  const config::MachineProfile& profile) {
  try {
    const std::string feature = text_or(body, "feature", "");
    const std::string action = text_or(body, "action", "");
    if (feature.empty()) throw Refused{400, "\"feature\" is missing"};
    if (action.empty()) throw Refused{400, "\"action\" is missing"};
    if (feature == "journal") return journal(action, body, profile);
    if (feature == "retrace") return retrace(action, body);
    if (feature == "electrode") return electrode(action, body);
    if (feature == "tool-guard") return tool_guard(action, body);
    throw Refused{400,
                  fmt::format("unknown feature \"{}\" (journal, retrace, electrode, tool-guard)", feature)};
  } catch (const Refused& r) {
    return ApiError{r.status, r.message};
  }
}

}  // namespace opencnc::hmi
