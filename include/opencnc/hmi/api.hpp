// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI's JSON API as plain functions: a command body to a typed controller::Request (with the
// checks that make a bad one a 4xx and change nothing), and status, events and outcomes to JSON.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/controller_status.hpp"
#include "opencnc/controller/events.hpp"
#include "opencnc/controller/observer.hpp"
#include "opencnc/controller/request.hpp"
#include "opencnc/hmi/simulation.hpp"

namespace opencnc::hmi {

/// Who may do what. Every call but the loopback status needs a token of one of these.
enum class Role : std::uint8_t {
  Operator,  ///< run, hold, jog, home, load programs, answer prompts
  Admin,     ///< also parameters, compensation tables, conditions and tool data
};

/// "operator", "admin". Any thread.
const char* to_string(Role r) noexcept;

/// A request the API refuses before it reaches the controller: the HTTP status and why.
struct ApiError {
  int status = 400;  ///< 400 malformed, 403 role, 404 no such program, 422 out of range
  std::string message;
};

/// What a command body asks for: a request for the controller, or a tool-table change (admin).
struct ToolChange {
  int tool = 0;
  std::optional<double> diameter_mm, z_offset_mm;
  std::string comment;
};
using Command = std::variant<controller::Request, ToolChange, SimulationEvent>;

/// The role a command kind needs (admin for tool data and the simulation, else operator); nothing for an
/// unknown kind.
std::optional<Role> role_for(std::string_view kind);

/// Turns a command body (`{"kind": …, …}`) into a request: every field checked for type and
/// range against the machine (axes configured, speeds within the axis' maximum, overrides in
/// their ranges, programs inside `programs_dir`). Any thread.
std::variant<Command, ApiError> parse_command(const nlohmann::json& body,
                                              const config::MachineProfile& profile,
                                              const std::filesystem::path& programs_dir);

/// A `{"kind": "feature", "feature": F, "action": A, …}` body to Request::feature(F, A, args):
/// the journal, retrace, electrode and tool-guard actions with their fields checked, the ones
/// that move the machine or change kept data only with `"confirmed": true` (docs/api.md,
/// "Features"). Any thread.
std::variant<controller::Request, ApiError> parse_feature_command(const nlohmann::json& body,
                                                                  const config::MachineProfile& profile);

/// The process side of the status: `power`, `load` (a load guard), `alarms` (the profile's
/// process alarms with their state), `edm` (a machine with [edm]). Any thread.
nlohmann::json process_json(const control::ServoStatus& s, const config::MachineProfile& profile);

/// The status as the API sends it (docs/api.md, "Status"). Any thread.
nlohmann::json status_json(const controller::ControllerStatus& s, const config::MachineProfile& profile);
/// One event of the log. Any thread.
nlohmann::json event_json(const controller::ControllerEvent& e);
/// A request's answer. Any thread.
nlohmann::json outcome_json(std::uint64_t id, const controller::Outcome& o);
/// The machine: axes with their limits, period, handwheel steps, override ranges. Any thread.
nlohmann::json machine_json(const config::MachineProfile& profile);

}  // namespace opencnc::hmi
