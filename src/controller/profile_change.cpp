// SPDX-License-Identifier: GPL-3.0-or-later
// Controller: the machine profile's editable keys changed while nothing moves — the file edited
// and loaded again, written back, the planner's limits and move checks swapped, the joints'
// limits and the tick's tables staged in the tick and applied by one command (all of them or
// none).
#include <fmt/format.h>

#include <algorithm>

#include "opencnc/control/stage_tables.hpp"
#include "opencnc/controller/controller.hpp"
#include "opencnc/controller/preflight.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/core/atomic_file.hpp"

namespace opencnc::controller {

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

control::JointLimits joint_limits(const control::ServoConfig& s, int joint) {
  const control::JointConfig& j = s.joints[static_cast<std::size_t>(joint)];
  control::JointLimits l{j.max_velocity, j.max_acceleration,    j.min_limit,
                         j.max_limit,    j.max_following_error, j.home.final_velocity};
  if (static_cast<std::size_t>(joint) < s.compensation.joints.size()) {
    const motion::JointCompensation& c = s.compensation.joints[static_cast<std::size_t>(joint)];
    l.backlash = c.backlash;
    l.takeup_velocity = c.max_velocity;
    l.takeup_acceleration = c.max_acceleration;
  }
  return l;
}

/// The homed joint of `next` whose axis stands outside its new soft limits, as a message; "".
std::string outside_new_limits(const control::ServoConfig& next, const control::ServoStatus& s) {
  for (int j = 0; j < next.joint_count; ++j) {
    const control::JointConfig& jc = next.joints[static_cast<std::size_t>(j)];
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
  servo_config_ = controller::servo_config(profile_);
  limits_ = machine_limits(profile_);
  check_ = make_move_check();
  ++limits_version_;  // the open program is checked again before it starts
  if (source_) source_->profile_changed(profile_);  // a program reads with the profile now in force
  std::lock_guard lock(out_mutex_);
  shown_profile_ = profile_;
}

// The request's checks, then the file (written first: if that fails nothing has changed), then
// the controller's side at once (so a request after this one plans with the new limits), then
// the tick's side; settle_profile_change() keeps it or puts everything back.
void Controller::edit_profile(std::uint64_t id, const requests::EditProfile& r) {
  const control::ServoStatus& s = servo();
  if (profile_change_)
    return finish(id, control::Refusal::Busy, "another change of the profile is being applied");
  if (job_ || s.activity != control::Activity::None || s.state == control::State::Running ||
      s.state == control::State::Held || s.state == control::State::Stopped)
    return finish(id, control::Refusal::Busy,
                  "machine parameters change only while nothing runs (no program, MDI line, jog or homing)");
  config::ProfileEditResult edit = config::edit_profile(profile_, r.edits, r.conditions);
  if (!edit.error.empty()) return finish(id, control::Refusal::BadValue, edit.error);
  if (!edit.ok()) {
    const Diagnostic* first = nullptr;
    for (const Diagnostic& d : edit.diagnostics.items())
      if (d.severity == Severity::Error && !first) first = &d;
    return finish(
        id, control::Refusal::BadValue,
        first ? "the profile refuses the change: " + first->format() : "the profile refuses the change",
        std::move(edit.diagnostics));
  }
  const control::ServoConfig next = controller::servo_config(*edit.profile);
  if (const std::string why = outside_new_limits(next, s); !why.empty())
    return finish(id, control::Refusal::SoftLimit, why);
  if (Diagnostics needs; *edit.deletes != '\0' && !open_program_passes(*edit.profile, needs)) {
    std::string why = needs.items().front().format();
    return finish(id, control::Refusal::ProgramError,
                  fmt::format("the open program selects {} this would delete: {}", edit.deletes, why),
                  std::move(needs));
  }
  std::string old_text, error;
  std::vector<config::FileText> old_files;  // a comp file the table is written into
  if (!write_files(edit.files, old_files, error)) return finish(id, control::Refusal::BadValue, error);
  if (!read_file(profile_.source, old_text, &error) ||
      !write_file_atomically(profile_.source, edit.text, &error)) {
    for (const config::FileText& back : old_files) write_file_atomically(back.path, back.text, nullptr);
    return finish(id, control::Refusal::BadValue,
                  fmt::format("{}: cannot write the profile: {}", profile_.source, error));
  }
  ProfileChange pending{id,
                        new_id(),
                        profile_,
                        std::move(old_text),
                        change_text(edit.changes),
                        r.who,
                        std::move(old_files),
                        edit.subject};
  swap_profile(std::move(*edit.profile));
  bool queued = true;
  for (int j = 0; j < next.joint_count && queued; ++j) {
    control::Command c;
    c.id = pending.stage_id;
    c.kind = control::CommandKind::StageJointLimits;
    c.axis = static_cast<std::int8_t>(j);
    c.limits = joint_limits(next, j);
    queued = send(c);
  }
  for (const control::Command& stage : stage_tables(*channels_, next, pending.stage_id)) {
    if (!queued) break;
    queued = send(stage);
  }
  control::Command apply;
  apply.id = id;
  apply.kind = control::CommandKind::ApplyJointLimits;
  profile_change_ = std::move(pending);
  if (!queued || !send(apply)) {
    control::ServoEvent refused;
    refused.kind = control::EventKind::Refused;
    refused.command_id = id;
    refused.refusal = control::Refusal::Busy;
    settle_profile_change(refused);  // the stages already queued are dropped by the next apply
  }
}

// An edit that deletes something the open program may need (a machining condition its M180
// selects): its preflight with the edited profile fails at the line that needs it. Those errors,
// the ones its preflight with the present profile from the same position has not, go to `needs`.
// The source is put back to the present profile either way (swap_profile() moves it on).
bool Controller::open_program_passes(const config::MachineProfile& next, Diagnostics& needs) {
  const std::optional<OpenProgram> op = source_ ? open_program() : std::nullopt;
  if (!op || op->path.empty()) return true;
  const Preflight now = preflight_file(op->path, servo().commanded, block_delete_, {});
  source_->profile_changed(next);
  const Preflight then = preflight_file(op->path, servo().commanded, block_delete_, {});
  source_->profile_changed(profile_);
  const auto same = [](const Diagnostic& a, const Diagnostic& b) {
    return a.code == b.code && a.file == b.file && a.line == b.line && a.message == b.message;
  };
  for (const Diagnostic& d : then.diagnostics.items()) {
    const auto& had = now.diagnostics.items();
    if (d.severity == Severity::Error &&
        std::none_of(had.begin(), had.end(), [&](const Diagnostic& x) { return same(x, d); }))
      needs.add(d);
  }
  return needs.items().empty();
}

bool Controller::settle_profile_change(const control::ServoEvent& e) {
  if (!profile_change_) return false;
  if (e.command_id == profile_change_->stage_id) return true;  // the apply answers for all
  if (e.command_id != profile_change_->id) return false;
  ProfileChange change = std::move(*profile_change_);
  profile_change_.reset();
  if (e.kind == control::EventKind::Accepted) {
    note(Severity::Note, "control.profile",
         fmt::format("{}{} changed: {} ({})", change.who.empty() ? "" : change.who + ": ", change.what,
                     change.message, profile_.source));
    finish(change.id, control::Refusal::None, change.message);
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
  finish(change.id, e.refusal == control::Refusal::None ? control::Refusal::Busy : e.refusal,
         error.empty() ? fmt::format("the machine would not take the new limits now: nothing changed")
                       : fmt::format("the machine would not take the new limits now, and a file could not be "
                                     "restored: {}",
                                     error));
  return true;
}

}  // namespace opencnc::controller
