// SPDX-License-Identifier: GPL-3.0-or-later
// Profile loading: read the file, parse TOML, apply overrides, read and check every section.
#include "opencnc/config/profile_loader.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "opencnc/core/atomic_file.hpp"
#include "overrides.hpp"
#include "sections.hpp"

namespace opencnc::config {

namespace detail {
/// [cut_chart], checked (read_cut_chart.cpp; config/cut_chart_profile.hpp reads it for the cutting
/// feature). Needs [process.plasma].
void read_cut_chart(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir);
}  // namespace detail

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
  Section top(root, "", {"name",  "description",  "servo_period_s", "axis",       "spindle",     "power",
                         "probe", "tool_changer", "process",        "io",         "interpreter", "planner",
                         "sim",   "interlocks",   "handwheel",      "tool_guard", "coupling",    "kinematics",
                         "edm",   "alarms",       "tool_change",    "cut_chart"},
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
  detail::read_kinematics(top, p);
  detail::read_process(top,
                       p);  // [process.cutting] names [io] channels, [process.broaching] the coupling's axes
  detail::read_edm(top, p);  // needs the axes and [process]
  detail::read_interpreter(top, p, base_dir);
  detail::read_planner(top, p);
  detail::read_tool_guard(top, p, base_dir);
  detail::read_cut_chart(top, p, base_dir);
  return p;
}

/// The most parts a dotted key may have ("axis.x.homing" has 3): the TOML parser builds a table per
/// part recursively, and 50,000 of them overflow the stack before any error could be given.
constexpr int kMaxKeyParts = 64;
/// A profile is a few kilobytes; a compensation table with thousands of points a few hundred.
constexpr std::size_t kMaxProfileBytes = 4u << 20;

/// Where a dotted key of more than kMaxKeyParts parts is (line, column: 1-based), if any. Counts
/// the dots of each line outside strings and comments, but those between two digits (1.5).
std::optional<std::pair<std::uint32_t, std::uint32_t>> too_many_key_parts(std::string_view text) {
  std::uint32_t line = 1, col = 0;
  int dots = 0;
  char quote = 0;  // inside "…" or '…' (triple quotes open and close the same way)
  bool comment = false, escaped = false;
  char before = '\n';
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    ++col;
    if (c == '\n') {
      ++line, col = 0, dots = 0, comment = false;  // a string stays open: triple quotes span lines
      before = c;
      continue;
    }
    if (comment) continue;
    if (quote != 0) {
      if (quote == '"' && c == '\\' && !escaped) {
        escaped = true;
        continue;
      }
      if (c == quote && !escaped) quote = 0;
      escaped = false;
      continue;
    }
    if (c == '#') {
      comment = true;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '.') {
      const char after = i + 1 < text.size() ? text[i + 1] : ' ';
      const bool decimal = before >= '0' && before <= '9' && after >= '0' && after <= '9';
      if (!decimal && ++dots >= kMaxKeyParts) return std::pair{line, col};
    }
    if (c != ' ' && c != '\t') before = c;
  }
  return std::nullopt;
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
  if (text.size() > kMaxProfileBytes) {
    out.diagnostics.error(std::string(source_name), 0, 0,
                          fmt::format("a profile is at most {} MiB (this text has {} bytes)",
                                      kMaxProfileBytes >> 20, text.size()),
                          "config.syntax");
    return out;
  }
  if (const auto at = too_many_key_parts(text)) {
    out.diagnostics.error(
        std::string(source_name), at->first, at->second,
        fmt::format("a dotted key of more than {} parts (no machine profile nests that deep)", kMaxKeyParts),
        "config.syntax");
    return out;
  }
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
