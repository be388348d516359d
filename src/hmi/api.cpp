// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI's JSON API: command bodies checked and turned into typed requests; status, events,
// outcomes and the machine as JSON.
#include "opencnc/hmi/api.hpp"

#include <cmath>
#include <map>

#include <fmt/format.h>

#include "opencnc/control/command.hpp"
#include "opencnc/hmi/api_admin.hpp"
#include "opencnc/run_from_line/run_from_line.hpp"
#include "opencnc/tools/tool_data.hpp"

namespace opencnc::hmi {

namespace {

using control::CommandKind;
using controller::Request;
using nlohmann::json;

/// Thrown inside parse_command for a field that is missing, mistyped or out of range.
struct Bad {
  int status;
  std::string message;
};

const std::map<std::string, CommandKind, std::less<>>& servo_kinds() {
  static const std::map<std::string, CommandKind, std::less<>> kinds{
      {"estop", CommandKind::EStop},
      {"reset", CommandKind::Reset},
      {"machine-on", CommandKind::MachineOn},
      {"machine-off", CommandKind::MachineOff},
      {"cycle-start", CommandKind::CycleStart},
      {"feed-hold", CommandKind::FeedHold},
      {"resume", CommandKind::Resume},
      {"abort", CommandKind::Abort},
      {"tool-changed", CommandKind::ToolChanged},
      {"spindle-off", CommandKind::SpindleOff},
      {"start-cut", CommandKind::StartCut},
  };
  return kinds;
}

const json& field(const json& body, const char* name) {
  const auto it = body.find(name);
  if (it == body.end()) throw Bad{400, fmt::format("\"{}\" is missing", name)};
  return *it;
}

double number(const json& body, const char* name) {
  const json& v = field(body, name);
  if (!v.is_number()) throw Bad{400, fmt::format("\"{}\" must be a number", name)};
  const double d = v.get<double>();
  if (!std::isfinite(d)) throw Bad{422, fmt::format("\"{}\" must be finite", name)};
  return d;
}

bool boolean(const json& body, const char* name) {
  const json& v = field(body, name);
  if (!v.is_boolean()) throw Bad{400, fmt::format("\"{}\" must be true or false", name)};
  return v.get<bool>();
}

std::string text(const json& body, const char* name) {
  const json& v = field(body, name);
  if (!v.is_string()) throw Bad{400, fmt::format("\"{}\" must be a string", name)};
  return v.get<std::string>();
}

const config::AxisProfile& axis(const json& body, const config::MachineProfile& p) {
  const std::string a = text(body, "axis");
  const std::string_view letters = "XYZABCUVW";
  const auto k = a.size() == 1
                     ? letters.find(static_cast<char>(std::toupper(static_cast<unsigned char>(a[0]))))
                     : std::string_view::npos;
  if (k == std::string_view::npos)
    throw Bad{400, fmt::format("\"axis\" must be one of X Y Z A B C U V W, not \"{}\"", a)};
  const config::AxisProfile* found = p.find(static_cast<Axis>(k));
  if (!found) throw Bad{422, fmt::format("this machine has no {} axis", letters[k])};
  return *found;
}

std::optional<Axis> optional_axis(const json& body, const config::MachineProfile& p) {
  if (!body.contains("axis") || body["axis"].is_null()) return std::nullopt;
  return axis(body, p).axis;
}

double within(double v, double lo, double hi, const char* name) {
  if (v < lo || v > hi) throw Bad{422, fmt::format("\"{}\" must be within {} … {}, not {}", name, lo, hi, v)};
  return v;
}

double axis_speed(const json& body, const char* name, const config::AxisProfile& a, bool signed_speed) {
  const double v = number(body, name);
  const double m = a.max_velocity;
  if (signed_speed ? std::abs(v) > m || v == 0 : v <= 0 || v > m) {
    throw Bad{422,
              fmt::format("\"{}\" must be {}within the axis' maximum of {} {}/s, not {}", name,
                          signed_speed ? "nonzero and " : "above 0 and ", m, a.rotary ? "deg" : "mm", v)};
  }
  return v;
}

Request override_request(const json& body) {
  const std::string which = text(body, "which");
  const double v = number(body, "value");
  if (which == "feed") return Request::feed_override(within(v, 0, 2, "value"));
  if (which == "spindle") return Request::spindle_override(within(v, 0, 2, "value"));
  if (which == "rapid") return Request::rapid_override(within(v, 0, 1, "value"));
  throw Bad{400, fmt::format("\"which\" must be feed, rapid or spindle, not \"{}\"", which)};
}

Request switch_request(const json& body) {
  const std::string which = text(body, "which");
  const bool on = boolean(body, "on");
  if (which == "single-block") return Request::single_block(on);
  if (which == "optional-stop") return Request::optional_stop(on);
  if (which == "block-delete") return Request::block_delete(on);
  throw Bad{400,
            fmt::format("\"which\" must be single-block, optional-stop or block-delete, not \"{}\"", which)};
}

Request mode_request(const json& body) {
  const std::string m = text(body, "mode");
  if (m == "manual") return Request::set_mode(control::Mode::Manual);
  if (m == "mdi") return Request::set_mode(control::Mode::Mdi);
  if (m == "auto") return Request::set_mode(control::Mode::Auto);
  throw Bad{400, fmt::format("\"mode\" must be manual, mdi or auto, not \"{}\"", m)};
}

/// A program named relative to the programs folder; nothing outside it (no "..", no absolute
/// path, no symlink out of it) and it must exist.
Request open_request(const json& body, const std::filesystem::path& dir) {
  const std::string name = text(body, "program");
  const std::filesystem::path rel(name);
  if (name.empty() || rel.is_absolute() || name.find('\0') != std::string::npos) {
    throw Bad{400, "\"program\" must name a file inside the programs folder"};
  }
  for (const auto& part : rel) {
    if (part == "..") throw Bad{400, "\"program\" must name a file inside the programs folder"};
  }
  std::error_code ec;
  const std::filesystem::path base = std::filesystem::weakly_canonical(dir, ec);
  const std::filesystem::path full = std::filesystem::weakly_canonical(dir / rel, ec);
  const auto [b, f] = std::mismatch(base.begin(), base.end(), full.begin(), full.end());
  if (ec || b != base.end()) throw Bad{400, "\"program\" must name a file inside the programs folder"};
  if (!std::filesystem::is_regular_file(full, ec)) throw Bad{404, fmt::format("no program \"{}\"", name)};
  return Request::open(full.string());
}

Request mdi_request(const json& body) {
  std::string line = text(body, "line");
  if (line.size() > 256) throw Bad{422, "\"line\" is longer than 256 characters"};
  if (line.find_first_of("\r\n", 0) != std::string::npos) throw Bad{400, "\"line\" must be one line"};
  return Request::mdi(std::move(line));
}

Request handwheel_request(const json& body, const config::MachineProfile& p) {
  if (!p.handwheel.present) throw Bad{422, "this machine has no handwheel"};
  const std::optional<Axis> a = optional_axis(body, p);
  const double step = a ? number(body, "step") : 0;
  if (a && std::find(p.handwheel.steps.begin(), p.handwheel.steps.end(), step) == p.handwheel.steps.end()) {
    throw Bad{422, fmt::format("\"step\" must be one of the machine's handwheel steps, not {}", step)};
  }
  return Request::handwheel(a, step);
}

ToolChange tool_change(const json& body) {
  const double t = number(body, "tool");
  if (t != std::floor(t) || t < 1 || t > 99999)
    throw Bad{422, "\"tool\" must be a tool number from 1 to 99999"};
  ToolChange c;
  c.tool = static_cast<int>(t);
  if (body.contains("diameter")) c.diameter_mm = within(number(body, "diameter"), 0, 1000, "diameter");
  if (body.contains("z_offset")) c.z_offset_mm = within(number(body, "z_offset"), -1000, 1000, "z_offset");
  if (body.contains("comment")) {
    c.comment = text(body, "comment");
    if (const auto why = tools::invalid_comment(c.comment)) throw Bad{422, *why};
  }
  if (!c.diameter_mm && !c.z_offset_mm && !body.contains("comment")) {
    throw Bad{400, "nothing to change: give \"diameter\", \"z_offset\" or \"comment\""};
  }
  return c;
}

/// A control of the simulated machine: the mains, an electrode (offsets and tip radius, mm), or
/// a cut's torque on the spindle (N·m).
SimulationEvent simulation_event(const json& body) {
  SimulationEvent e{text(body, "event")};
  if (e.event == "electrode") {
    const json& o = field(body, "offset");
    if (!o.is_array() || o.size() != 3 || !o[0].is_number() || !o[1].is_number() || !o[2].is_number())
      throw Bad{400, "\"offset\" must be [X, Y, Z] in mm"};
    for (std::size_t i = 0; i < 3; ++i) e.offset_mm[i] = within(o[i].get<double>(), -1000, 1000, "offset");
    e.tip_radius_mm = within(number(body, "tip_radius"), 0, 100, "tip_radius");
  } else if (e.event == "spindle-load") {
    e.torque_nm = within(number(body, "torque_nm"), 0, 100000, "torque_nm");
  } else if (e.event != "mains-off" && e.event != "mains-on") {
    throw Bad{400, fmt::format("\"event\" must be mains-off, mains-on, electrode or spindle-load, not \"{}\"",
                               e.event)};
  }
  return e;
}

Command parse(const json& body, const config::MachineProfile& p, const std::filesystem::path& dir) {
  if (!body.is_object()) throw Bad{400, "the body must be a JSON object"};
  const std::string kind = text(body, "kind");
  if (const auto it = servo_kinds().find(kind); it != servo_kinds().end()) return Request::simple(it->second);
  if (kind == "mode") return mode_request(body);
  if (kind == "jog") {
    const config::AxisProfile& a = axis(body, p);
    return Request::jog(a.axis, axis_speed(body, "velocity", a, true));
  }
  if (kind == "jog-by") {
    const config::AxisProfile& a = axis(body, p);
    const double d = number(body, "distance");
    const double span = a.max_limit - a.min_limit;
    if (d == 0 || (!a.wrapped && std::abs(d) > span)) {
      throw Bad{422, fmt::format("\"distance\" must be nonzero and within the axis' travel of {}", span)};
    }
    return Request::jog_by(a.axis, d, axis_speed(body, "speed", a, false));
  }
  if (kind == "jog-stop") return Request::jog_stop(optional_axis(body, p));
  if (kind == "home") return Request::home(optional_axis(body, p));
  if (kind == "seek-limit") {
    const config::AxisProfile& a = axis(body, p);
    const std::string d = text(body, "direction");
    if (d != "+" && d != "-")
      throw Bad{400, "\"direction\" must be \"+\" or \"-\" (the limit switch sought)"};
    return Request::seek_limit(a.axis, d == "+" ? 1 : -1);
  }
  if (kind == "override") return override_request(body);
  if (kind == "switch") return switch_request(body);
  if (kind == "spindle-on") {
    const double rpm = within(number(body, "rpm"), 0, p.spindle.max_rpm, "rpm");
    return Request::spindle_on(rpm, body.contains("clockwise") ? boolean(body, "clockwise") : true);
  }
  if (kind == "coolant") {
    const std::string which = text(body, "which");
    if (which != "flood" && which != "mist") throw Bad{400, "\"which\" must be flood or mist"};
    return Request::coolant(which == "flood" ? control::Coolant::Flood : control::Coolant::Mist,
                            boolean(body, "on"));
  }
  if (kind == "handwheel") return handwheel_request(body, p);
  if (kind == "open") return open_request(body, dir);
  if (kind == "mdi") return mdi_request(body);
  if (kind == "set-tool") return tool_change(body);
  if (kind == "set-parameters") {
    ParametersRequest r = parameters_request(body, p);
    if (!r.request) throw Bad{r.status, r.message};
    return std::move(*r.request);
  }
  if (kind == "set-compensation") {
    ParametersRequest r = compensation_request(body, p);
    if (!r.request) throw Bad{r.status, r.message};
    return std::move(*r.request);
  }
  if (kind == "set-conditions") {
    ParametersRequest r = conditions_request(body, p);
    if (!r.request) throw Bad{r.status, r.message};
    return std::move(*r.request);
  }
  if (kind == "add-condition" || kind == "delete-condition") {
    ParametersRequest r = condition_change_request(body, p, kind == "delete-condition");
    if (!r.request) throw Bad{r.status, r.message};
    return std::move(*r.request);
  }
  if (kind == "run-from-line") {
    const double line = number(body, "line");
    if (line != std::floor(line) || line < 1 || line > 1e9)
      throw Bad{422, "\"line\" must be a line number from 1"};
    return Request::feature("run-from-line", "start",
                            run_from_line::RunFromLineArgs{static_cast<std::uint32_t>(line)});
  }
  if (kind == "simulate") return simulation_event(body);
  if (kind == "feature") {
    auto r = parse_feature_command(body, p);
    if (auto* e = std::get_if<ApiError>(&r)) throw Bad{e->status, e->message};
    return std::get<Request>(std::move(r));
  }
  throw Bad{400, fmt::format("unknown command kind \"{}\" (docs/api.md lists them)", kind)};
}

json axes_json(const Pose& p, int count, const config::MachineProfile& profile) {
  json j = json::object();
  for (int k = 0; k < count && k < static_cast<int>(profile.axes.size()); ++k) {
    const Axis a = profile.axes[static_cast<std::size_t>(k)].axis;
    j[std::string(1, letter(a))] = p[index(a)];
  }
  return j;
}

const char* wait_name(control::Wait w) {
  static constexpr const char* names[] = {
      "",       "dwell", "spindle", "tool-changer", "manual-tool-change", "input",
      "orient", "probe", "starved", "hand-axis",    "interlock"};
  return names[static_cast<std::size_t>(w)];
}

const char* activity_name(control::Activity a) {
  static constexpr const char* names[] = {"", "jog", "homing", "program"};
  return names[static_cast<std::size_t>(a)];
}

const char* stop_name(control::StopReason r) {
  static constexpr const char* names[] = {"", "program-stop", "optional-stop", "single-block"};
  return names[static_cast<std::size_t>(r)];
}

const char* severity_name(Severity s) {
  return s == Severity::Error ? "error" : s == Severity::Warning ? "warning" : "note";
}

json location_json(const controller::SourceLocation& l) {
  return {{"file", l.file}, {"line", l.line}, {"calls", l.calls}};
}

}  // namespace

const char* to_string(Role r) noexcept {
  return r == Role::Admin ? "admin" : "operator";
}

std::optional<Role> role_for(std::string_view kind) {
  static const char* const operator_kinds[] = {
      "mode",       "jog",     "jog-by",    "jog-stop", "home", "override",      "switch",
      "spindle-on", "coolant", "handwheel", "open",     "mdi",  "run-from-line", "seek-limit"};
  if (kind == "set-tool" || kind == "set-parameters" || kind == "set-compensation" ||
      kind == "set-conditions" || kind == "add-condition" || kind == "delete-condition" || kind == "simulate")
    return Role::Admin;
  if (kind == "feature") return Role::Operator;  // the confirmation is in the body (api_features.cpp)
  if (servo_kinds().find(kind) != servo_kinds().end()) return Role::Operator;
  for (const char* k : operator_kinds) {
    if (kind == k) return Role::Operator;
  }
  return std::nullopt;
}

std::variant<Command, ApiError> parse_command(const json& body, const config::MachineProfile& profile,
                                              const std::filesystem::path& programs_dir) {
  try {
    return parse(body, profile, programs_dir);
  } catch (const Bad& b) {
    return ApiError{b.status, b.message};
  }
}

json status_json(const controller::ControllerStatus& s, const config::MachineProfile& profile) {
  const control::ServoStatus& v = s.servo;
  json fe = json::object(), homed = json::object(), seek = json::object();
  for (const config::AxisProfile& a : profile.axes) {
    const auto& j = v.joints[static_cast<std::size_t>(a.joint)];
    fe[std::string(1, letter(a.axis))] = j.following_error;
    homed[std::string(1, letter(a.axis))] = j.homed;
    const control::LimitSeekStatus& k = v.seek[static_cast<std::size_t>(a.joint)];
    if (k.direction == 0) continue;  // never sought
    seek[std::string(1, letter(a.axis))] = {{"phase", control::to_string(k.phase)},
                                            {"direction", k.direction > 0 ? "+" : "-"},
                                            {"found", k.found},
                                            {"tripped_at", k.tripped_at},
                                            {"rest_at", k.rest_at}};
  }
  const int n = static_cast<int>(profile.axes.size());
  json j = {
      {"tick", v.tick},
      {"time_s", v.time_s},
      {"state", control::to_string(v.state)},
      {"mode", control::to_string(v.mode)},
      {"activity", activity_name(v.activity)},
      {"wait", wait_name(v.wait)},
      {"stop_reason", stop_name(v.stop_reason)},
      {"wait_text", s.wait_text},
      {"machine", axes_json(v.actual, n, profile)},
      {"commanded", axes_json(v.commanded, n, profile)},
      {"work", axes_json(controller::work_position(v.actual, s.offsets), n, profile)},
      {"distance_to_go", axes_json(s.distance_to_go, n, profile)},
      {"offsets",
       {{"system", controller::work_system_name(s.offsets.system)},
        {"g5x", axes_json(s.offsets.g5x, n, profile)},
        {"g92", axes_json(s.offsets.g92, n, profile)},
        {"tool", axes_json(s.offsets.tool, n, profile)},
        {"xy_rotation_deg", s.offsets.xy_rotation_deg}}},
      {"following_error", fe},
      {"homed", homed},
      {"all_homed", v.all_homed},
      {"seek", seek},
      {"path_velocity", v.path_velocity},
      {"feed_override", v.feed_override},
      {"rapid_override", v.rapid_override},
      {"spindle_override", v.spindle_override},
      {"single_block", v.single_block},
      {"optional_stop", v.optional_stop},
      {"spindle",
       {{"rpm", v.spindle_rpm},
        {"rpm_actual", v.spindle_rpm_actual},
        {"at_speed", v.spindle_at_speed},
        {"torque_nm", v.spindle_torque_valid ? json(v.spindle_torque_nm) : json()},
        {"direction", v.spindle_direction == machine::SpindleDirection::Stopped     ? "stopped"
                      : v.spindle_direction == machine::SpindleDirection::Clockwise ? "cw"
                                                                                    : "ccw"}}},
      {"flood", v.flood},
      {"mist", v.mist},
      {"tool", v.tool},
      {"prepared_tool", v.prepared_tool},
      {"fault", s.fault_text},
      {"program", {{"name", s.program_name}, {"moves", s.program_moves}, {"length_mm", s.program_length_mm}}},
      {"job",
       {{"kind", controller::to_string(s.job)},
        {"id", s.job_id},
        {"name", s.job_name},
        {"active", s.run_active},
        {"segment", s.run_segment},
        {"progress", s.progress},
        {"location", location_json(s.location)},
        {"interpreter", location_json(s.interpreter)}}},
      {"sync_wait", controller::to_string(s.sync_wait)},
      {"runs_finished", s.runs_finished},
      {"limits_version", s.limits_version},
  };
  j.update(process_json(v, profile));
  return j;
}

json event_json(const controller::ControllerEvent& e) {
  json j{{"seq", e.seq},
         {"tick", e.tick},
         {"kind", controller::to_string(e.kind)},
         {"severity", severity_name(e.severity)},
         {"code", e.code},
         {"text", e.text}};
  switch (e.kind) {
    case controller::ControllerEventKind::Answer:
      j["request"] = e.request_id;
      j["accepted"] = e.accepted;
      break;
    case controller::ControllerEventKind::JobStarted:
    case controller::ControllerEventKind::JobEnded:
      j["job"] = {{"kind", controller::to_string(e.job)}, {"id", e.job_id}};
      if (e.kind == controller::ControllerEventKind::JobEnded) {
        j["end"] = controller::to_string(e.end);
        j["location"] = location_json(e.location);
      }
      break;
    case controller::ControllerEventKind::SyncWait:
    case controller::ControllerEventKind::SyncDone:
      j["sync"] = controller::to_string(e.sync);
      j["location"] = location_json(e.location);
      break;
    default:
      break;
  }
  return j;
}

json outcome_json(std::uint64_t id, const controller::Outcome& o) {
  json diags = json::array();
  for (const Diagnostic& d : o.diagnostics.items()) {
    diags.push_back({{"severity", severity_name(d.severity)}, {"text", d.format()}, {"code", d.code}});
  }
  return {{"id", id},
          {"accepted", o.accepted},
          {"code", o.accepted ? "" : control::refusal_code(o.refusal)},
          {"message", o.message},
          {"diagnostics", diags}};
}

/// The limit switches the axis can seek ("-", "+").
static json seek_sides(const config::AxisProfile& a) {
  json sides = json::array();
  if (a.seek.velocity <= 0) return sides;
  if (a.switches.limit_neg.present) sides.push_back("-");
  if (a.switches.limit_pos.present) sides.push_back("+");
  return sides;
}

json machine_json(const config::MachineProfile& p) {
  json axes = json::array();
  for (const config::AxisProfile& a : p.axes) {
    axes.push_back({{"axis", std::string(1, letter(a.axis))},
                    {"rotary", a.rotary},
                    {"manual", a.manual()},
                    {"min_limit", a.min_limit},
                    {"max_limit", a.max_limit},
                    {"max_velocity", a.max_velocity},
                    {"max_acceleration", a.max_acceleration},
                    {"homing", a.homing.method != config::HomingMethod::Immediate},
                    {"seek", seek_sides(a)}});
  }
  return {{"name", p.name},
          {"description", p.description},
          {"servo_period_s", p.servo_period_s},
          {"axes", axes},
          {"spindle_max_rpm", p.spindle.max_rpm},
          {"tool_changer", p.tool_changer},
          {"handwheel", p.handwheel.present ? json(p.handwheel.steps) : json(nullptr)},
          {"overrides", {{"feed", {0, 2}}, {"spindle", {0, 2}}, {"rapid", {0, 1}}}}};
}

}  // namespace opencnc::hmi
