// SPDX-License-Identifier: GPL-3.0-or-later
// Changing a loaded profile's editable keys: which keys, the edit of the file's text (one key at a
// time, comments kept), and the new profile validated by the profile's own loader.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::config {

/// One key set to a new value: `key` dotted as the file has it ("axis.x.max_velocity"), `value`
/// as TOML text ("80.0").
struct ProfileKeyEdit {
  std::string key;
  std::string value;
};

/// A parameter the admin may change while the machine is idle, with its present value.
struct EditableParameter {
  std::string key;   ///< "axis.x.max_velocity"
  double value = 0;  ///< in the profile's units
  std::string unit;  ///< "mm/s", "mm/s²", "mm", "deg/s" …
  std::string what;  ///< one line for the screen
};

/// The editable parameters of `profile`, axis by axis (per axis: max_velocity, max_acceleration,
/// min_limit and max_limit unless wrapped, max_following_error; with a compensation table its
/// backlash and take-up limits). Any thread.
std::vector<EditableParameter> editable_parameters(const MachineProfile& profile);

/// True for a key of an axis' pitch-error table the admin may change through edit_profile():
/// `axis.<a>.compensation.forward`, `.reverse` (one-line TOML arrays: the errors moving in + and
/// in −, one per point), `.start`, `.interval` (the points' positions), or for a table in a comp
/// file `.positions` (one-line TOML array: each point's position). Any thread.
bool is_pitch_table_key(std::string_view key);

/// A field of a machining condition (`[[edm.condition]]`) the admin may change: the key in the
/// file, its unit, one line for the screen, and for a choice its words ("+|-").
struct ConditionField {
  const char* key;      ///< "on_time_us"
  const char* unit;     ///< "µs", "A", "V", "mm/s" … ("" for a choice)
  const char* what;     ///< one line for the screen
  const char* choices;  ///< "+|-", "axis|path", "none|circle|square|star"; nullptr for a number
};

/// The editable fields of every machining condition, in the Conditions screen's order (the
/// generator's, the gap servo's, the jump's, the orbit's). Any thread.
std::span<const ConditionField> condition_fields();

/// The field `field` of `c` as TOML-free text for the audit and the screen ("100.0", "+",
/// "circle"); "" for a field that is not editable. Any thread.
std::string condition_field_text(const machine::EdmCondition& c, std::string_view field);

/// The numeric field `field` of `c`; nullopt for a choice (condition_field_text gives its word)
/// or a field that is not editable. Any thread.
std::optional<double> condition_field_number(const machine::EdmCondition& c, std::string_view field);

/// True for a key of a machining condition the admin may change through edit_profile():
/// `edm.condition.<number>.<field>`, a field of condition_fields(). Any thread.
bool is_condition_key(std::string_view key);

/// A machining condition added or deleted through edit_profile(): `number` added as a copy of
/// condition `from` (every key its `[[edm.condition]]` element sets: the generator, gap servo,
/// jump, orbit, side gap and wear ratio), or deleted (`remove`).
struct ConditionChange {
  int number = 0;
  bool remove = false;
  int from = 0;  ///< an add's source: a condition of the profile
};

/// The condition a new condition `number` is copied from when the admin names none: the one with
/// the highest number below it, else the lowest; 0 when `edm` has none. Any thread.
int condition_to_copy(const machine::EdmConfig& edm, int number);

/// One key's change, as text for the audit and the answer ("100.0" → "80.0").
struct ProfileChange {
  std::string key;
  std::string old_value, new_value;
};

/// What edit_profile() made: the new profile and its file's text, or why not.
struct ProfileEditResult {
  std::optional<MachineProfile> profile;
  std::string text;                    ///< the profile file's new text
  /// Other files the change writes, with their new text (an axis' comp file); the loader checked
  /// the profile with these texts in place of the files.
  std::vector<FileText> files;
  std::vector<ProfileChange> changes;  ///< in the order asked
  std::string error;                   ///< a refusal of the request itself (a key not editable …)
  Diagnostics diagnostics;             ///< the loader's on the new text (`file:line:col: message`)
  /// What the change is of, for the audit and the log: "machining conditions" when every change
  /// is a condition's, else "machine parameters".
  const char* subject = "machine parameters";
  /// What the change deletes, for a refusal when the open program still needs it ("a condition");
  /// "" when it deletes nothing.
  const char* deletes = "";
  bool ok() const noexcept { return profile.has_value(); }
};

/// The profile `live` (loaded from `live.source` with `live.overrides`) with `edits` applied: the
/// file is read again and must still be the text `live` was loaded from (its digest); each key
/// must be one of editable_parameters(live), or a pitch-table key (is_pitch_table_key) of an axis
/// with `[axis.<a>.compensation]`, or a condition key (is_condition_key) of a condition the
/// profile defines, and not set by an override; its line is edited with with_toml_value() (a
/// condition's in its `[[edm.condition]]` element). A table written as `errors` stays so while
/// forward and reverse are equal; when they differ, `errors` gives way to `forward` and `reverse`
/// (the section's comments stay). A table in a LinuxCNC comp file is written into that file
/// instead (CompFileEdits: forward, reverse and positions; its comment lines stay), returned in
/// `files`. The new text is loaded by parse_profile() with the same overrides and those files' new
/// texts, so its errors are the loader's own, at the edited line (of the profile or of the comp
/// file). With `conditions`, machining conditions are added after the keys are set (each a new
/// `[[edm.condition]]` element after the last one, with_toml_element_copy()), then deleted (the
/// element and the comment above it, without_toml_element()); refused when a number to add exists
/// or is not 1–99, a copy's source or a condition to delete does not exist (or is deleted and
/// changed at once), the table would hold more than machine::kMaxEdmConditions or none. Nothing
/// is written. Non-real-time (reads the files).
ProfileEditResult edit_profile(const MachineProfile& live, std::span<const ProfileKeyEdit> edits,
                               std::span<const ConditionChange> conditions = {});

}  // namespace opencnc::config
