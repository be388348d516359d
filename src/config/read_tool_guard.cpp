// SPDX-License-Identifier: GPL-3.0-or-later
// [tool_guard]: where the tool store is, when the check runs, its tolerances and its M-code.
#include <fmt/format.h>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

enum class When : std::uint8_t { Off, Start, ToolChange, Both };

}  // namespace

void read_tool_guard(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir) {
  const toml::table* t = top.subtable("tool_guard");
  if (t == nullptr) return;
  Section s(*t, "tool_guard",
            {"store", "check", "geometry_tolerance", "base_tolerance", "wear_band", "check_mcode"},
            top.reporter());
  ToolGuardProfile& g = profile.tool_guard;
  g.present = true;
  if (const auto store = s.string("store")) {
    const std::filesystem::path p(*store);
    g.store = (p.is_absolute() || base_dir.empty() ? p : base_dir / p).lexically_normal().string();
  } else if (!s.has("store")) {
    s.missing("store");
  }
  if (!profile.interpreter.tool_table.empty() && !g.store.empty()) {
    s.error("store",
            "tool_guard.store and interpreter.tool_table both name the live tool table: keep one (import the "
            ".tbl "
            "into the store with `opencnc tools --db STORE import FILE`)",
            "config.conflict");
  }
  const When when = s.choice<When>("check",
                                   {{"off", When::Off},
                                    {"start", When::Start},
                                    {"tool-change", When::ToolChange},
                                    {"start-and-tool-change", When::Both}},
                                   When::Both);
  g.check_at_start = when == When::Start || when == When::Both;
  g.check_at_tool_change = when == When::ToolChange || when == When::Both;
  g.geometry_tolerance_mm = s.number_or("geometry_tolerance", g.geometry_tolerance_mm, Bound::NonNegative);
  g.base_tolerance_mm = s.number_or("base_tolerance", g.base_tolerance_mm, Bound::NonNegative);
  g.wear_band_mm = s.number_or("wear_band", g.wear_band_mm, Bound::NonNegative);
  if (const auto m = s.integer("check_mcode", 0, 199)) {
    if (*m != 0 && *m < 100)
      s.error("check_mcode",
              fmt::format(
                  "tool_guard.check_mcode must be a user M-code from 100 to 199 (or 0: none); it is {}", *m),
              "config.range");
    else
      g.check_mcode = static_cast<int>(*m);
  }
}

}  // namespace opencnc::config::detail
