// SPDX-License-Identifier: GPL-3.0-or-later
// [cut_chart]: where the plasma table's cut chart is, the material in force at first, the check's
// tolerances (docs/cutting.md, "Cut charts"). Checked with the profile; read again from its file by
// the cutting feature (the chart is the feature's, not the tick's: MachineProfile does not carry it).
#include <fmt/format.h>

#include "opencnc/config/cut_chart_profile.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "overrides.hpp"
#include "sections.hpp"

namespace opencnc::config {

namespace detail {

void read_cut_chart(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir);

namespace {

void read_section(Section& top, const MachineProfile& profile, const std::filesystem::path& base_dir,
                  CutChartProfile& c, bool& present) {
  const toml::table* t = top.subtable("cut_chart");
  present = t != nullptr;
  if (t == nullptr) return;
  Section s(*t, "cut_chart", {"store", "material", "feed_tolerance", "kerf_tolerance"}, top.reporter());
  if (!profile.plasma.present)
    s.error("store", "[cut_chart] needs a plasma table ([process.plasma]): its materials drive the torch",
            "config.conflict");
  if (const auto store = s.string("store")) {
    const std::filesystem::path p(*store);
    c.store = (p.is_absolute() || base_dir.empty() ? p : base_dir / p).lexically_normal().string();
  } else if (!s.has("store")) {
    s.missing("store");
  }
  if (const auto m = s.integer("material", 0, 99999)) c.material = static_cast<int>(*m);
  c.feed_tolerance = s.number_or("feed_tolerance", c.feed_tolerance, Bound::NonNegative);
  c.kerf_tolerance_mm = s.number_or("kerf_tolerance", c.kerf_tolerance_mm, Bound::NonNegative);
}

}  // namespace

void read_cut_chart(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir) {
  CutChartProfile checked;
  bool present = false;
  read_section(top, profile, base_dir, checked, present);
}

}  // namespace detail

std::optional<CutChartProfile> cut_chart_profile(const MachineProfile& profile, Diagnostics& diags) {
  if (profile.source.empty() || !profile.plasma.present) return std::nullopt;
  std::string text, why;
  if (!read_file(profile.source, text, &why)) {
    diags.error(profile.source, 0, 0, "cannot read the profile again for its [cut_chart]: " + why,
                "config.file");
    return std::nullopt;
  }
  const std::size_t errors = diags.error_count();
  detail::Reporter r(diags, profile.source);
  toml::table root;
  try {
    root = toml::parse(text, profile.source);
  } catch (const toml::parse_error& e) {
    r.error(&e.source(), fmt::format("TOML syntax: {}", e.description()), "config.syntax");
    return std::nullopt;
  }
  if (!detail::apply_overrides(root, profile.overrides, r)) return std::nullopt;
  const toml::table* t = root.get_as<toml::table>("cut_chart");
  if (t == nullptr) return std::nullopt;
  toml::table only;
  only.insert("cut_chart", *t);
  detail::Section top(only, "", {"cut_chart"}, r);
  CutChartProfile c;
  bool present = false;
  detail::read_section(top, profile, std::filesystem::path(profile.source).parent_path(), c, present);
  if (diags.error_count() > errors || !present) return std::nullopt;
  return c;
}

}  // namespace opencnc::config
