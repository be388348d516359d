// SPDX-License-Identifier: GPL-3.0-or-later
// Profile loading: read the file, parse TOML, apply overrides, read and check every section.
#include "opencnc/config/profile_loader.hpp"

#include <fmt/format.h>

#include "opencnc/core/atomic_file.hpp"
#include "overrides.hpp"
#include "sections.hpp"

namespace opencnc::config {

namespace {

using detail::Bound;
using detail::Reporter;
using detail::Section;

void read_identity(Section& top, MachineProfile& p) {
  if (const auto name = top.string("name")) {
    p.name = *name;
    if (p.name.empty()) top.error("name", "name must not be empty", "config.range");
  } else if (!top.has("name")) {
    top.missing("name");
  }
  p.description = top.string("description").value_or("");
  p.servo_period_s = top.number_or("servo_period_s", p.servo_period_s, Bound::Positive);
  if (p.servo_period_s < 1e-5 || p.servo_period_s > 0.1) {
    top.error("servo_period_s",
              fmt::format("servo_period_s must be between 0.00001 and 0.1 s (it is {})",
                          detail::show(p.servo_period_s)),
              "config.range");
    p.servo_period_s = 0.001;  // go on checking the rest against a sane period
  }
}

MachineProfile read_profile(const toml::table& root, Reporter& r, const std::filesystem::path& base_dir,
                            std::span<const FileText> files) {
  Section top(root, "", {"name",   "description",  "servo_period_s", "axis",       "spindle",     "power",
                         "probe",  "tool_changer", "process",        "io",         "interpreter", "planner",
                         "sim",    "interlocks",   "handwheel",      "tool_guard", "coupling",    "edm",
                         "alarms", "tool_change"},
              r);
  MachineProfile p;
  read_identity(top, p);
  detail::read_sim(top, p);
  detail::read_axes(top, p);
  detail::read_compensation(top, p, base_dir, files);
  detail::read_spindle(top, p);
  detail::read_power(top, p);
  detail::read_probe(top, p);
  detail::read_tool_changer(top, p);
  detail::read_tool_change(top, p);
  detail::read_io(top, p);
  detail::read_interlocks(top, p);
  detail::read_alarms(top, p);
  detail::read_handwheel(top, p);
  detail::read_coupling(top, p);
  detail::read_process(top,
                       p);  // [process.cutting] names [io] channels, [process.broaching] the coupling's axes
  detail::read_edm(top, p);  // needs the axes and [process]
  detail::read_interpreter(top, p, base_dir);
  detail::read_planner(top, p);
  detail::read_tool_guard(top, p, base_dir);
  return p;
}

}  // namespace

std::uint64_t text_digest(std::string_view text) noexcept {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a, 64 bits
  for (const char c : text) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return h;
}

ProfileLoad parse_profile(std::string_view text, std::string_view source_name,
                          std::span<const std::string> overrides, const std::filesystem::path& base_dir,
                          std::span<const FileText> files) {
  ProfileLoad out;
  Reporter r(out.diagnostics, std::string(source_name));
  toml::table root;
  try {
    root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    r.error(&e.source(), fmt::format("TOML syntax: {}", e.description()), "config.syntax");
    return out;
  }
  if (!detail::apply_overrides(root, overrides, r)) return out;
  MachineProfile p = read_profile(root, r, base_dir, files);
  if (r.has_errors()) return out;
  p.source = std::string(source_name);
  p.overrides.assign(overrides.begin(), overrides.end());
  p.source_digest = text_digest(text);
  out.profile = std::move(p);
  return out;
}

ProfileLoad load_profile(const std::filesystem::path& file, std::span<const std::string> overrides) {
  std::string text, why;
  if (!read_file(file.string(), text, &why)) {  // (a folder says so here, not as an empty profile)
    ProfileLoad out;
    out.diagnostics.error(file.string(), 0, 0, "cannot read the profile: " + why, "config.file");
    return out;
  }
  return parse_profile(text, file.string(), overrides, file.parent_path());
}

}  // namespace opencnc::config
