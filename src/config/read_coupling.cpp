// SPDX-License-Identifier: GPL-3.0-or-later
// [coupling]: the master and slave axes of the broaching codes, the master position the tick
// follows, and the pitch and cam tables programs name by number.
#include <fmt/format.h>

#include <cmath>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

/// The limits of the tick's fixed-size copy (motion::kMaxCouplingTables, kMaxCouplingPoints).
constexpr std::size_t kMaxTables = 8;
constexpr std::size_t kMaxPoints = 64;

std::optional<Axis> read_axis_letter(Section& s, std::string_view key, const MachineProfile& p) {
  const auto word = s.string(key);
  if (!word) {
    if (!s.has(key)) s.missing(key);
    return std::nullopt;
  }
  const auto axis = axis_from_letter(*word);
  if (!axis || p.find(*axis) == nullptr) {
    s.error(key, fmt::format("{} must name an axis of this machine (it is \"{}\")", s.key_path(key), *word),
            "config.range");
    return std::nullopt;
  }
  return axis;
}

// Points with increasing master offsets; a pitch table's pitches all of one sign and not 0.
void read_points(Section& t, CouplingTableProfile& table) {
  const toml::node* n = t.find("points");
  const std::string shape = fmt::format("{} must be an array of [master offset, value] pairs (2 to {})",
                                        t.key_path("points"), kMaxPoints);
  const toml::array* rows = n != nullptr ? n->as_array() : nullptr;
  if (rows == nullptr || rows->size() < 2 || rows->size() > kMaxPoints) {
    if (n == nullptr) {
      t.missing("points");
    } else {
      t.error("points", shape, "config.type");
    }
    return;
  }
  for (const toml::node& row : *rows) {
    const auto point = number_pair(row);
    if (!point || !std::isfinite(point->first) || !std::isfinite(point->second)) {
      t.reporter().error(&row.source(), shape, "config.type");
      return;
    }
    const auto [m, v] = *point;
    if (!table.points.empty() && m <= table.points.back().first) {
      t.reporter().error(&row.source(),
                         fmt::format("{}: master offsets must increase ({} follows {})", t.key_path("points"),
                                     show(m), show(table.points.back().first)),
                         "config.range");
      return;
    }
    const bool pitch = table.kind == CouplingTableProfile::Kind::Pitch;
    if (pitch && (v == 0 || (!table.points.empty() && (v > 0) != (table.points.front().second > 0)))) {
      t.reporter().error(&row.source(),
                         fmt::format("{}: a pitch must not be 0 and all pitches of a table share their sign",
                                     t.key_path("points")),
                         "config.range");
      return;
    }
    table.points.emplace_back(m, v);
  }
}

void read_tables(Section& s, CouplingProfile& c) {
  const toml::node* n = s.find("table");
  if (n == nullptr) return;
  const toml::array* list = n->as_array();
  if (list == nullptr || !list->is_array_of_tables() || list->size() > kMaxTables) {
    s.error(
        "table",
        fmt::format("coupling.table must be an array of tables ([[coupling.table]]), at most {}", kMaxTables),
        "config.type");
    return;
  }
  for (std::size_t i = 0; i < list->size(); ++i) {
    Section t(*(*list)[i].as_table(), fmt::format("coupling.table[{}]", i + 1), {"kind", "points"},
              s.reporter());
    CouplingTableProfile table;
    table.kind = t.choice<CouplingTableProfile::Kind>(
        "kind", {{"pitch", CouplingTableProfile::Kind::Pitch}, {"cam", CouplingTableProfile::Kind::Cam}},
        CouplingTableProfile::Kind::Pitch);
    if (!t.has("kind")) t.missing("kind");
    read_points(t, table);
    c.tables.push_back(std::move(table));
  }
}

}  // namespace

void read_coupling(Section& top, MachineProfile& profile) {
  const toml::table* t = top.subtable("coupling");
  if (t == nullptr) return;
  Section s(*t, "coupling",
            {"master", "slave", "source", "radius_mm", "engage_tolerance_um", "engage_timeout_s", "table"},
            top.reporter());
  CouplingProfile& c = profile.coupling;
  c.present = true;
  const auto master = read_axis_letter(s, "master", profile);
  const auto slave = read_axis_letter(s, "slave", profile);
  if (master) c.master = *master;
  if (slave) c.slave = *slave;
  if (master && slave) {
    const AxisProfile& m = *profile.find(*master);
    const AxisProfile& sl = *profile.find(*slave);
    if (*master == *slave) s.error("slave", "coupling.slave must not be the master axis", "config.range");
    if (m.rotary)
      s.error("master", "coupling.master must be a linear axis (the law's offsets are mm)", "config.range");
    if (!sl.rotary)
      s.error("slave", "coupling.slave must be a rotary axis (the law gives degrees)", "config.range");
    if (m.manual() || sl.manual())
      s.error(m.manual() ? "master" : "slave", "a coupled axis must be driven, not fed by hand",
              "config.range");
  }
  c.radius_mm = s.number_or("radius_mm", c.radius_mm, Bound::Positive);
  c.engage_tolerance_um = s.number_or("engage_tolerance_um", c.engage_tolerance_um, Bound::NonNegative);
  c.engage_timeout_s = s.number_or("engage_timeout_s", c.engage_timeout_s, Bound::Positive);
  c.from_actual = s.choice<bool>("source", {{"command", false}, {"actual", true}}, false);
  read_tables(s, c);
}

}  // namespace opencnc::config::detail
