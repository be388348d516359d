// SPDX-License-Identifier: GPL-3.0-or-later
// The admin's part of the JSON API: machine parameters (the profile's editable keys) read and
// changed through the controller's EditProfile request.
#pragma once

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
  std::optional<control::Request> request;
  int status = 400;
  std::string message;
};
ParametersRequest parameters_request(const nlohmann::json& body, const config::MachineProfile& profile);

/// `GET /api/v1/parameters`: the profile's file and its editable parameters with their values,
/// units and a line each. Any thread.
nlohmann::json parameters_json(const config::MachineProfile& profile);

}  // namespace opencnc::hmi
