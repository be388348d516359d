// SPDX-License-Identifier: GPL-3.0-or-later
// The editable keys of a profile and an edit of them: the file's text changed key by key, then
// loaded again by the profile loader (its own checks and messages).
#include "opencnc/config/profile_edit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "opencnc/config/comp_file_edit.hpp"
#include "condition_edit.hpp"
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

const AxisProfile* axis_named(const MachineProfile& p, std::string_view letter_lower) {
  for (const AxisProfile& a : p.axes)
    if (letter_lower.size() == 1 && std::tolower(letter(a.axis)) == letter_lower[0]) return &a;
  return nullptr;
}

/// "axis.x.compensation.forward" → ("x", "forward"); nullopt for any other key.
std::optional<std::pair<std::string, std::string>> pitch_key_parts(std::string_view key) {
  const std::string k = lower(key);
  constexpr std::string_view head = "axis.", mid = ".compensation.";
  if (k.size() < head.size() + 1 + mid.size() || k.compare(0, head.size(), head) != 0) return std::nullopt;
  const std::string axis = k.substr(head.size(), 1);
  if (k.compare(head.size() + 1, mid.size(), mid) != 0) return std::nullopt;
  std::string name = k.substr(head.size() + 1 + mid.size());
  if (name != "forward" && name != "reverse" && name != "start" && name != "interval" && name != "positions")
    return std::nullopt;
  return std::pair{axis, name};
}

/// The table's present value of a pitch-table key, as text for the audit ("13 points", "50.0").
std::string table_text(const CompensationProfile& c, const std::string& name) {
  if (name == "start") return c.positions.empty() ? "none" : toml_number(c.positions.front());
  if (name == "interval")
    return c.positions.size() < 2 ? "none" : toml_number(c.positions[1] - c.positions[0]);
  return fmt::format("{} points", c.positions.size());
}

/// How a direction's errors changed: "13 points → 13 points, 3 changed (largest 0.002 at 100.0)".
std::string table_change(const CompensationProfile& before, const CompensationProfile& after, bool forward) {
  const std::vector<double>& a = forward ? before.forward : before.reverse;
  const std::vector<double>& b = forward ? after.forward : after.reverse;
  if (a.size() != b.size() || before.positions != after.positions) return fmt::format("{} points", b.size());
  std::size_t changed = 0, worst = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (a[i] == b[i]) continue;
    if (changed++ == 0 || std::abs(b[i] - a[i]) > std::abs(b[worst] - a[worst])) worst = i;
  }
  if (changed == 0) return fmt::format("{} points, unchanged", b.size());
  return fmt::format("{} points, {} changed (largest {} → {} at {})", b.size(), changed,
                     toml_number(a[worst]), toml_number(b[worst]), toml_number(after.positions[worst]));
}

/// The edits of one axis' forward and reverse errors as lines of `text`: `errors` kept while both
/// are equal, else replaced by forward and reverse. Returns false with `error`.
bool edit_directions(std::string& text, const AxisProfile& a, const std::string& base,
                     const std::optional<std::string>& forward, const std::optional<std::string>& reverse,
                     std::string& error) {
  std::optional<std::string> next;
  if (a.compensation.one_table) {
    if (!forward || !reverse) {
      error = fmt::format("{} is one table for both directions (errors): give forward and reverse together",
                          base);
      return false;
    }
    if (*forward == *reverse) {
      next = with_toml_value(text, base + ".errors", *forward, error);
      if (next) text = std::move(*next);
      return next.has_value();
    }
    next = without_toml_key(text, base + ".errors", error);
    if (!next) return false;
    text = std::move(*next);
  }
  for (const auto& [name, value] : {std::pair{"forward", &forward}, std::pair{"reverse", &reverse}}) {
    if (!*value) continue;
    next = with_toml_value(text, base + "." + name, **value, error);
    if (!next) return false;
    text = std::move(*next);
  }
  return true;
}

/// `text` with `key` set to `value` (with_toml_value()); false with the refusal in `r.error`,
/// prefixed by the profile's file.
bool set_key(std::string& text, const std::string& key, const std::string& value, const std::string& source,
             ProfileEditResult& r) {
  std::string error;
  std::optional<std::string> next = with_toml_value(text, key, value, error);
  if (!next) {
    r.error = fmt::format("{}: {}", source, error);
    return false;
  }
  text = std::move(*next);
  return true;
}

}  // namespace

bool is_pitch_table_key(std::string_view key) {
  return pitch_key_parts(key).has_value();
}

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

ProfileEditResult edit_profile(const MachineProfile& live, std::span<const ProfileKeyEdit> edits,
                               std::span<const ConditionChange> conditions) {
  ProfileEditResult r;
  if (edits.empty() && conditions.empty()) {
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
  struct Directions {
    const AxisProfile* axis = nullptr;
    std::optional<std::string> forward, reverse;
  };
  std::vector<Directions> directions;
  CompFileEdits comp_files;
  for (const ProfileKeyEdit& e : edits) {
    const std::string key = lower(e.key);
    if (const auto parts = pitch_key_parts(key)) {
      const AxisProfile* a = axis_named(live, parts->first);
      const std::string base = fmt::format("axis.{}.compensation", parts->first);
      if (!a || !a->compensation.present) {
        r.error = fmt::format("{} is not a parameter that can be changed here: the profile has no [{}]",
                              e.key, base);
        return r;
      }
      if (!a->compensation.comp_file.empty()) {  // written into that file (comp_file_edit.cpp)
        if (!comp_files.add(*a, parts->second, e.value, r.error)) return r;
        r.changes.push_back({key, table_text(a->compensation, parts->second), e.value});
        continue;
      }
      if (parts->second == "positions") {
        r.error = fmt::format(
            "{}: the profile's table has its points at start + k·interval: give start and interval", e.key);
        return r;
      }
      if (overridden(live, key)) {
        r.error = fmt::format(
            "{} is set by an override (--set) at start: the file's value would not take effect", key);
        return r;
      }
      r.changes.push_back({key, table_text(a->compensation, parts->second), e.value});
      if (parts->second == "forward" || parts->second == "reverse") {
        auto d = std::find_if(directions.begin(), directions.end(),
                              [&](const Directions& x) { return x.axis == a; });
        if (d == directions.end()) d = directions.insert(directions.end(), Directions{a, {}, {}});
        (parts->second == "forward" ? d->forward : d->reverse) = e.value;
        continue;
      }
      if (!set_key(text, key, e.value, live.source, r)) return r;
      continue;
    }
    if (key.rfind("edm.condition.", 0) == 0) {
      if (!detail::edit_condition(text, live, key, e.value, r.changes.emplace_back(), r.error)) return r;
      continue;
    }
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
    if (!set_key(text, key, e.value, live.source, r)) return r;
    r.changes.push_back({key, toml_number(*old), e.value});
  }
  for (const Directions& d : directions) {
    std::string error;
    const std::string base =
        fmt::format("axis.{}.compensation", static_cast<char>(std::tolower(letter(d.axis->axis))));
    if (!edit_directions(text, *d.axis, base, d.forward, d.reverse, error)) {
      r.error = fmt::format("{}: {}", live.source, error);
      return r;
    }
  }
  if (!conditions.empty() && !detail::change_conditions(text, live, conditions, edits, r.changes, r.error))
    return r;
  if (!comp_files.texts(r.files, r.error)) return r;
  ProfileLoad load = parse_profile(text, live.source, live.overrides,
                                   std::filesystem::path(live.source).parent_path(), r.files);
  r.diagnostics = std::move(load.diagnostics);
  if (!load.profile) return r;
  const std::vector<EditableParameter> now = editable_parameters(*load.profile);
  for (ProfileChange& c : r.changes) {
    if (c.key.rfind("edm.condition.", 0) == 0 && !is_condition_key(c.key)) continue;  // added, deleted
    if (is_condition_key(c.key)) {
      c.new_value = detail::condition_value(*load.profile, c.key);
      continue;
    }
    const auto parts = pitch_key_parts(c.key);
    if (!parts) {
      c.new_value = toml_number(value_of(now, c.key).value_or(0));
      continue;
    }
    const CompensationProfile& after = axis_named(*load.profile, parts->first)->compensation;
    const CompensationProfile& before = axis_named(live, parts->first)->compensation;
    c.new_value = parts->second == "forward" || parts->second == "reverse"
                      ? table_change(before, after, parts->second == "forward")
                      : table_text(after, parts->second);
  }
  r.profile = std::move(load.profile);
  r.text = std::move(text);
  if (std::all_of(r.changes.begin(), r.changes.end(),
                  [](const ProfileChange& c) { return c.key.rfind("edm.condition.", 0) == 0; }))
    r.subject = "machining conditions";
  if (std::any_of(conditions.begin(), conditions.end(), [](const ConditionChange& c) { return c.remove; }))
    r.deletes = "a condition";
  return r;
}

}  // namespace opencnc::config
