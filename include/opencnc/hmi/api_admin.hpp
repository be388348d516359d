// SPDX-License-Identifier: GPL-3.0-or-later
// The admin's part of the JSON API: machine parameters (the profile's editable keys), the
// pitch-error compensation tables and an EDM's machining conditions, read and changed through the
// controller's EditProfile request.
#pragma once

#include <map>
#include <utility>

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/request.hpp"

namespace opencnc::hmi {

/// A `set-parameters` body (`{"values": {"axis.x.max_velocity": 80, …}}`) as the controller's
/// EditProfile request, or the HTTP status and message of why not (400 malformed, 422 a key
/// that is not editable or a value that is not a finite number). Any thread.
struct ParametersRequest {
  std::optional<controller::Request> request;
  int status = 400;
  std::string message;
};
ParametersRequest parameters_request(const nlohmann::json& body, const config::MachineProfile& profile);

/// `GET /api/v1/parameters`: the profile's file and its editable parameters with their values,
/// units and a line each. Any thread.
nlohmann::json parameters_json(const config::MachineProfile& profile);

/// A `set-compensation` body (`{"axis": "X", "forward": [...], "reverse": [...]}`, optionally
/// `start`, `interval`, `backlash`) as the controller's EditProfile request of that axis' keys
/// `axis.<a>.compensation.*`, or the HTTP status and message of why not (400 malformed, 422 an
/// axis without compensation, a table from a comp file, a table of 0 or more than 256 points,
/// a value that is not a finite number). The loader's own checks (slopes, forward and reverse
/// of one length) come from the controller. Any thread.
ParametersRequest compensation_request(const nlohmann::json& body, const config::MachineProfile& profile);

/// `GET /api/v1/compensation`: per axis with `[axis.<a>.compensation]`, its backlash, take-up
/// limits and pitch-error table (positions, forward, reverse, whether one table for both ways,
/// the comp file it came from and whether it can be changed here). Any thread.
nlohmann::json compensation_json(const config::MachineProfile& profile);

/// `GET /api/v1/conditions`: an EDM's machining conditions (`[[edm.condition]]`) in the order of
/// the profile, each with its generator, gap-servo, jump and orbit settings, and the fields the
/// admin may change (key, unit, a line, the words of a choice); an empty list on a machine
/// without `[edm]`. Any thread.
nlohmann::json conditions_json(const config::MachineProfile& profile);

/// `GET /api/v1/edm-sequence?area=…&finish=…&undersize=…[&surface=…&depth=…]`: the
/// roughing-to-finishing condition sequence (edm/sequence.hpp) as {status 200, {"steps": [...],
/// "text", "program"}} (the program with a depth only), or {400 or 422, {"message"}} saying why
/// not (a missing or malformed value, a machine without [edm], what the table does not allow).
/// Any thread.
std::pair<int, nlohmann::json> edm_sequence_json(const config::MachineProfile& profile,
                                                 const std::map<std::string, std::string>& query);

/// A `set-conditions` body (`{"condition": 3, "values": {"on_time_us": 60, "polarity": "-"}}`) as
/// the controller's EditProfile request of the keys `edm.condition.<n>.<field>`, or the HTTP
/// status and message of why not (400 malformed or a value of the wrong type, 422 a condition the
/// profile lacks, a field that cannot be changed, a number that is not finite or a word that is
/// not one of the choice's). The loader's own checks come from the controller. Any thread.
ParametersRequest conditions_request(const nlohmann::json& body, const config::MachineProfile& profile);

/// An `add-condition` body (`{"condition": 4, "from": 3}`: condition 4 added as a copy of 3;
/// without `from` a copy of the condition with the highest number below it, else of the lowest)
/// or, with `remove`, a `delete-condition` body (`{"condition": 9}`) as the controller's
/// EditProfile request of that change, or the HTTP status and message of why not (400 malformed,
/// 422 a machine without conditions, a number outside 1–99, a condition to add that exists, one
/// to copy or delete that does not). The table's size, the last condition and the open program
/// are the controller's checks. Any thread.
ParametersRequest condition_change_request(const nlohmann::json& body, const config::MachineProfile& profile,
                                           bool remove);

}  // namespace opencnc::hmi
