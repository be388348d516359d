// SPDX-License-Identifier: GPL-3.0-or-later
// What opencnc keeps in its stores, as JSON: the shape the API and the command line's --json both
// show (docs/api.md, docs/cutting.md, docs/tools.md).
#pragma once

#include <nlohmann/json.hpp>

#include "opencnc/store/cut_chart.hpp"
#include "opencnc/store/tool_store.hpp"

namespace opencnc::hmi {

/// One material of a cut chart: every field by its CSV name (`number` an integer, `name` and
/// `process` text, the rest numbers).
nlohmann::json material_json(const store::Material& m);

/// One audited change: `{"at_utc", "interface", "reason", "what", "old", "new"}`.
nlohmann::json audit_json(const store::AuditEntry& e);

}  // namespace opencnc::hmi
