// SPDX-License-Identifier: GPL-3.0-or-later
// Stores' records as JSON (hmi/store_json.hpp).
#include "opencnc/hmi/store_json.hpp"

#include <string>
#include <string_view>

namespace opencnc::hmi {

nlohmann::json material_json(const store::Material& m) {
  nlohmann::json j;
  for (const store::MaterialField& f : store::material_fields()) {
    const std::string_view name = f.name;
    if (name == "name" || name == "process")
      j[f.name] = store::field_text(m, name);
    else if (name == "number")
      j[f.name] = m.number;
    else
      j[f.name] = store::field_number(m, name);
  }
  return j;
}

nlohmann::json audit_json(const store::AuditEntry& e) {
  return {{"at_utc", e.at_utc}, {"interface", e.interface}, {"reason", e.reason},
          {"what", e.what},     {"old", e.old_value},       {"new", e.new_value}};
}

}  // namespace opencnc::hmi
