// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart in the API: `GET /api/v1/cutchart` (the materials, the selection, the fields, the
// last changes) and `POST /api/v1/cutchart` (select a material; an admin sets or removes one),
// straight on the store the machine's `[cut_chart]` names (docs/api.md, docs/cutting.md).
#pragma once

#include <nlohmann/json.hpp>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/hmi/api.hpp"

namespace opencnc::hmi {

/// An answer: its HTTP status and body.
struct CutChartAnswer {
  int status = 200;
  nlohmann::json body;
};

/// `GET /api/v1/cutchart`: `{"store", "selected", "fields": [{"name", "required"}], "materials":
/// [{number, name, …}], "audit": [the last 20 changes]}`; 404 on a machine without `[cut_chart]`.
/// Blocking (SQLite); any thread.
CutChartAnswer cut_chart_get(const config::MachineProfile& profile);

/// `POST /api/v1/cutchart` with `{"action": "select", "material": n}` (either role; 0: none),
/// `{"action": "set", "material": {"number": n, …fields}}` or `{"action": "remove", "material": n}`
/// (an admin's: else 403). The change is one transaction of the store, audited as "hmi"; a material
/// the chart's checks refuse is a 422 naming the field, and changes nothing. Answers the chart as
/// GET does. Blocking (SQLite); any thread.
CutChartAnswer cut_chart_post(const config::MachineProfile& profile, const nlohmann::json& body, Role role);

}  // namespace opencnc::hmi
