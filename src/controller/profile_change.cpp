// SPDX-License-Identifier: GPL-3.0-or-later
// Controller: the machine profile's editable keys changed while nothing moves — the file edited
// and loaded again, written back, the planner's limits and move checks swapped, the joints'
// limits, pitch tables and EDM conditions staged in the tick and applied by one command (all of
// them or none).
#include <fmt/format.h>

#include <algorithm>

#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/preflight.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/core/atomic_file.hpp"

namespace opencnc::control {

namespace {

/// Writes each of `files` atomically, keeping what each held in `old` (for a later put back);
/// on a failure puts back those written and returns false with `error`.
bool write_files(const std::vector<config::FileText>& files, std::vector<config::FileText>& old,
                 std::string& error) {
  for (const config::FileText& f : files) {
    config::FileText was{f.path, {}};
    std::string why;
    if (!read_file(f.path, was.text, &why) || !write_file_atomically(f.path, f.text, &why)) {
      error = fmt::format("{}: cannot write: {}", f.path, why);
      for (const config::FileText& back : old) write_file_atomically(back.path, back.text, nullptr);
      old.clear();
      return false;
    }
    old.push_back(std::move(was));
  }
  return true;
}

std::string change_text(const std::vector<config::ProfileChange>& changes) {
  std::string s;
  for (const config::ProfileChange& c : changes)
    s += fmt::format("{}{} {} → {}", s.empty() ? "" : "; ", c.key, c.old_value, c.new_value);
  return s;
}

/// True when every change is of a machining condition (`edm.condition.…`): the audit says so.
bool only_conditions(const std::vector<config::ProfileChange>& changes) {
  return std::all_of(changes.begin(), changes.end(),
                     [](const config::ProfileChange& c) { return c.key.rfind("edm.condition.", 0) == 0; });
}

JointLimits joint_limits(const ServoConfig& s, int joint) {
  const JointConfig& j = s.joints[static_cast<std::size_t>(joint)];
  JointLimits l{j.max_velocity, j.max_acceleration,    j.min_limit,
                j.max_limit,    j.max_following_error, j.home.final_velocity};
  if (static_cast<std::size_t>(joint) < s.compensation.joints.size()) {
    const motion::JointCompensation& c = s.compensation.joints[static_cast<std::size_t>(joint)];
    l.backlash = c.backlash;
    l.takeup_velocity = c.max_velocity;
    l.takeup_acceleration = c.max_acceleration;
  }
  return l;
}

/// Bit j: joint j is compensated in `next` (its table is staged at every change, changed or not:
/// a stage left in the tick by a change whose commands did not all fit in the ring is then
/// always overwritten before the next apply; an unchanged table switches without any take-up).
std::uint16_t compensated_joints(const ServoConfig& next) {
  std::uint16_t mask = 0;
  for (int j = 0; j < next.joint_count && j < motion::kMaxCompensatedJoints; ++j)
    if (next.compensation.joints[static_cast<std::size_t>(j)].enabled)
      mask = static_cast<std::uint16_t>(mask | (1u << j));
  return mask;
}

/// The homed joint of `next` whose axis stands outside its new soft limits, as a message; "".
std::string outside_new_limits(const ServoConfig& next, const ServoStatus& s) {
  for (int j = 0; j < next.joint_count; ++j) {
    const JointConfig& jc = next.joints[static_cast<std::size_t>(j)];
    if (!s.joints[static_cast<std::size_t>(j)].homed || jc.wrapped || jc.drive == machine::JointDrive::Manual)
      continue;
    const double x = s.commanded[jc.axis];
    if (x < jc.min_limit || x > jc.max_limit)
      return fmt::format(
          "{} stands at {:.4f}, outside the new soft limits {:.4f} … {:.4f}: move it inside first",
          kAxisLetters[static_cast<std::size_t>(jc.axis)], x, jc.min_limit, jc.max_limit);
  }
  return {};
}

}  // namespace

config::MachineProfile Controller::current_profile() const {
  std::lock_guard lock(out_mutex_);
  return shown_profile_;
}

void Controller::swap_profile(config::MachineProfile profile) {
  profile_ = std::move(profile);
  servo_config_ = control::servo_config(profile_);
  limits_ = machine_limits(profile_);
  check_ = std::make_unique<MachineMoveCheck>(servo_config_, limits_);
  ++limits_version_;  // the open program is checked again before it starts
  if (source_) source_->profile_changed(profile_);  // M180 selects from the conditions now defined
  std::lock_guard lock(out_mutex_);
  shown_profile_ = profile_;
}

// The request's checks, then the file (written first: if that fails nothing has changed), then
// the controller's side at once (so a request after this one plans with the new limits), then
// the tick's side; settle_profile_change() keeps it or puts everything back.
void Controller::edit_profile(std::uint64_t id, const requests::EditProfile& r) {
  const ServoStatus& s = servo();
  if (profile_change_) return finish(id, Refusal::Busy, "another change of the profile is being applied");
  if (job_ || s.activity != Activity::None || s.state == State::Running || s.state == State::Held ||
      s.state == State::Stopped)
    return finish(id, Refusal::Busy,
                  "machine parameters change only while nothing runs (no program, MDI line, jog or homing)");
  config::ProfileEditResult edit = config::edit_profile(profile_, r.edits, r.conditions);
  if (!edit.error.empty()) return finish(id, Refusal::BadValue, edit.error);
  if (!edit.ok()) {
    const Diagnostic* first = nullptr;
    for (const Diagnostic& d : edit.diagnostics.items())
      if (d.severity == Severity::Error && !first) first = &d;
    return finish(
        id, Refusal::BadValue,
        first ? "the profile refuses the change: " + first->format() : "the profile refuses the change",
        std::move(edit.diagnostics));
  }
  const ServoConfig next = control::servo_config(*edit.profile);
  if (const std::string why = outside_new_limits(next, s); !why.empty())
    return finish(id, Refusal::SoftLimit, why);
  if (Diagnostics selects; !open_program_keeps_its_conditions(r, *edit.profile, selects)) {
    std::string why = selects.items().front().format();
    return finish(id, Refusal::ProgramError,
                  fmt::format("the open program selects a condition this would delete: {}", why),
                  std::move(selects));
  }
  std::string old_text, error;
  std::vector<config::FileText> old_files;  // a comp file the table is written into
  if (!write_files(edit.files, old_files, error)) return finish(id, Refusal::BadValue, error);
  if (!read_file(profile_.source, old_text, &error) ||
      !write_file_atomically(profile_.source, edit.text, &error)) {
    for (const config::FileText& back : old_files) write_file_atomically(back.path, back.text, nullptr);
    return finish(id, Refusal::BadValue,
                  fmt::format("{}: cannot write the profile: {}", profile_.source, error));
  }
  ProfileChange pending{
      id, new_id(), profile_, std::move(old_text), change_text(edit.changes), r.who, std::move(old_files),
      only_conditions(edit.changes) ? "machining conditions" : "machine parameters"};
  const std::uint16_t tables = compensated_joints(next);
  swap_profile(std::move(*edit.profile));
  bool queued = true;
  for (int j = 0; j < next.joint_count && queued; ++j) {
    Command c;
    c.id = pending.stage_id;
    c.kind = CommandKind::StageJointLimits;
    c.axis = static_cast<std::int8_t>(j);
    c.limits = joint_limits(next, j);
    queued = send(c);
  }
  for (int j = 0; j < motion::kMaxCompensatedJoints && queued; ++j)
    if (tables & (1u << j)) queued = stage_pitch_table(j, next, pending);
  if (next.edm.enabled && queued) queued = stage_edm_conditions(next, pending);
  Command apply;
  apply.id = id;
  apply.kind = CommandKind::ApplyJointLimits;
  profile_change_ = std::move(pending);
  if (!queued || !send(apply)) {
    ServoEvent refused;
    refused.kind = EventKind::Refused;
    refused.command_id = id;
    refused.refusal = Refusal::Busy;
    settle_profile_change(refused);  // the stages already queued are dropped by the next apply
  }
}

// A condition deleted that the open program selects: its preflight with the edited profile's
// conditions fails at the line of its M180 (`edm.condition`), and those errors go to `selects`.
// The source is put back to the present profile either way (swap_profile() moves it on).
bool Controller::open_program_keeps_its_conditions(const requests::EditProfile& r,
                                                   const config::MachineProfile& next, Diagnostics& selects) {
  const bool deletes = std::any_of(r.conditions.begin(), r.conditions.end(),
                                   [](const config::ConditionChange& c) { return c.remove; });
  const std::optional<OpenProgram> op = deletes && source_ ? open_program() : std::nullopt;
  if (!op || op->path.empty()) return true;
  source_->profile_changed(next);
  const Preflight pf = preflight_file(op->path, servo().commanded, block_delete_, {});
  source_->profile_changed(profile_);
  constexpr std::string_view code = "edm.condition";
  for (const Diagnostic& d : pf.diagnostics.items())
    if (d.severity == Severity::Error && d.code.size() >= code.size() &&
        d.code.compare(d.code.size() - code.size(), code.size(), code) == 0)
      selects.add(d);
  return selects.items().empty();
}

// The joint's new table into the buffer its tick does not read, as the tick publishes it (not as
// this controller remembers it: the tick may have outlived the controller that switched it).
// Nothing else is in flight: one change at a time. Named by a StagePitchTable. Returns false when
// the ring is full.
bool Controller::stage_pitch_table(int joint, const ServoConfig& next, const ProfileChange& pending) {
  const auto j = static_cast<std::size_t>(joint);
  const motion::JointCompensation& c = next.compensation.joints[j];
  const std::int8_t reading = channels_->pitch_tables.reading[j].index.load(std::memory_order_acquire);
  const auto buffer = static_cast<std::uint8_t>(reading == 0 ? 1 : 0);
  channels_->pitch_tables.joints[j][buffer] = c.pitch;
  Command stage;
  stage.id = pending.stage_id;
  stage.kind = CommandKind::StagePitchTable;
  stage.axis = static_cast<std::int8_t>(joint);
  stage.table_buffer = buffer;
  return send(stage);
}

// The machining conditions into the channels' table (the tick reads it only in the apply, and no
// other change is in flight), named by a StageEdmConditions: staged at every change of an EDM's
// profile, changed or not, as the pitch tables are. Returns false when the ring is full.
bool Controller::stage_edm_conditions(const ServoConfig& next, const ProfileChange& pending) {
  channels_->edm_conditions.conditions = next.edm.conditions;
  channels_->edm_conditions.count = next.edm.condition_count;
  Command stage;
  stage.id = pending.stage_id;
  stage.kind = CommandKind::StageEdmConditions;
  return send(stage);
}

bool Controller::settle_profile_change(const ServoEvent& e) {
  if (!profile_change_) return false;
  if (e.command_id == profile_change_->stage_id) return true;  // the apply answers for all
  if (e.command_id != profile_change_->id) return false;
  ProfileChange change = std::move(*profile_change_);
  profile_change_.reset();
  if (e.kind == EventKind::Accepted) {
    note(Severity::Note, "control.profile",
         fmt::format("{}{} changed: {} ({})", change.who.empty() ? "" : change.who + ": ", change.what,
                     change.message, profile_.source));
    finish(change.id, Refusal::None, change.message);
    return true;
  }
  // The tick said no (something started moving meanwhile): the files and the limits as they were.
  std::string error;
  std::vector<config::FileText> files = std::move(change.old_files);
  files.push_back({profile_.source, std::move(change.old_text)});
  for (const config::FileText& back : files)
    if (std::string why; !write_file_atomically(back.path, back.text, &why))
      error += fmt::format("{}{}: {}", error.empty() ? "" : "; ", back.path, why);
  swap_profile(std::move(change.old_profile));
  finish(change.id, e.refusal == Refusal::None ? Refusal::Busy : e.refusal,
         error.empty() ? fmt::format("the machine would not take the new limits now: nothing changed")
                       : fmt::format("the machine would not take the new limits now, and a file could not be "
                                     "restored: {}",
                                     error));
  return true;
}

}  // namespace opencnc::control
