// SPDX-License-Identifier: GPL-3.0-or-later
// The editable keys of a profile and an edit of them: the file's text changed key by key, then
// loaded again by the profile loader (its own checks and messages).
#include "opencnc/config/profile_edit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/config/toml_edit.hpp"
#include "opencnc/core/atomic_file.hpp"

namespace opencnc::config {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string axis_key(const AxisProfile& a, std::string_view name) {
  return fmt::format("axis.{}.{}", static_cast<char>(std::tolower(letter(a.axis))), name);
}

/// The override of `key` among `overrides` ("axis.X.max_velocity=50"), if any.
bool overridden(const MachineProfile& p, const std::string& key) {
  return std::any_of(p.overrides.begin(), p.overrides.end(), [&](const std::string& o) {
    const std::size_t eq = o.find('=');
    std::string_view k(o.data(), eq == std::string::npos ? o.size() : eq);
    while (!k.empty() && (k.back() == ' ' || k.back() == '\t')) k.remove_suffix(1);
    while (!k.empty() && (k.front() == ' ' || k.front() == '\t')) k.remove_prefix(1);
    return lower(k) == key;
  });
}

std::optional<double> value_of(const std::vector<EditableParameter>& params, const std::string& key) {
  for (const EditableParameter& p : params) {
    if (p.key == key) return p.value;
  }
  return std::nullopt;
}

}  // namespace

std::vector<EditableParameter> editable_parameters(const MachineProfile& profile) {
  std::vector<EditableParameter> out;
  for (const AxisProfile& a : profile.axes) {
    const std::string unit = a.rotary ? "deg" : "mm";
    out.push_back({axis_key(a, "max_velocity"), a.max_velocity, unit + "/s", "fastest speed of the axis"});
    out.push_back(
        {axis_key(a, "max_acceleration"), a.max_acceleration, unit + "/s²", "largest acceleration"});
    if (!a.wrapped) {
      out.push_back(
          {axis_key(a, "min_limit"), a.min_limit, unit, "soft limit, low end (machine coordinates)"});
      out.push_back(
          {axis_key(a, "max_limit"), a.max_limit, unit, "soft limit, high end (machine coordinates)"});
    }
    out.push_back({axis_key(a, "max_following_error"), a.max_following_error, unit,
                   "largest following error before a fault"});
    if (a.compensation.present) {
      out.push_back({axis_key(a, "compensation.backlash"), a.compensation.backlash, unit,
                     "backlash: lost motion on a reversal"});
      out.push_back({axis_key(a, "compensation.takeup_velocity"), a.compensation.takeup_velocity, unit + "/s",
                     "fastest motion of the compensation's own correction"});
      out.push_back({axis_key(a, "compensation.takeup_acceleration"), a.compensation.takeup_acceleration,
                     unit + "/s²", "largest acceleration of the compensation's own correction"});
    }
  }
  return out;
}

ProfileEditResult edit_profile(const MachineProfile& live, std::span<const ProfileKeyEdit> edits) {
  ProfileEditResult r;
  if (edits.empty()) {
    r.error = "no parameter to change";
    return r;
  }
  if (live.source.empty()) {
    r.error = "the profile was not read from a file: there is nothing to write the change to";
    return r;
  }
  std::string text, why;
  if (!read_file(live.source, text, &why)) {
    r.error = fmt::format("{}: cannot read the profile: {}", live.source, why);
    return r;
  }
  if (text_digest(text) != live.source_digest) {
    r.error = fmt::format(
        "{} changed on disk since the controller loaded it: restart the controller to load it "
        "before changing parameters here",
        live.source);
    return r;
  }
  const std::vector<EditableParameter> params = editable_parameters(live);
  for (const ProfileKeyEdit& e : edits) {
    const std::string key = lower(e.key);
    const std::optional<double> old = value_of(params, key);
    if (!old) {
      r.error = fmt::format("{} is not a parameter that can be changed here", e.key);
      return r;
    }
    if (overridden(live, key)) {
      r.error = fmt::format(
          "{} is set by an override (--set) at start: the file's value would not take effect", key);
      return r;
    }
    std::string error;
    std::optional<std::string> next = with_toml_value(text, key, e.value, error);
    if (!next) {
      r.error = fmt::format("{}: {}", live.source, error);
      return r;
    }
    text = std::move(*next);
    r.changes.push_back({key, toml_number(*old), e.value});
  }
  ProfileLoad load =
      parse_profile(text, live.source, live.overrides, std::filesystem::path(live.source).parent_path());
  r.diagnostics = std::move(load.diagnostics);
  if (!load.profile) return r;
  const std::vector<EditableParameter> now = editable_parameters(*load.profile);
  for (ProfileChange& c : r.changes) c.new_value = toml_number(value_of(now, c.key).value_or(0));
  r.profile = std::move(load.profile);
  r.text = std::move(text);
  return r;
}

}  // namespace opencnc::config
