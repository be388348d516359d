// SPDX-License-Identifier: GPL-3.0-or-later
// Request — what a front end (CLI, HMI, a feature) asks the controller for, one typed struct per
// kind. Servo commands become control::Command for the tick; the rest is the controller's.
#pragma once

#include <any>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "opencnc/canon/program.hpp"
#include "opencnc/config/profile_edit.hpp"
#include "opencnc/control/command.hpp"
#include "opencnc/core/axes.hpp"

namespace opencnc::controller {

/// Which override a SetOverride request sets (ranges: feed and spindle 0–2, rapid 0–1).
enum class OverrideKind : std::uint8_t { Feed, Rapid, Spindle };

/// Which operator switch a SetSwitch request sets.
enum class SwitchKind : std::uint8_t {
  SingleBlock,   ///< stop after every block
  OptionalStop,  ///< M1 stops
  BlockDelete,   ///< skip lines that start with '/' (in programs opened from now on)
};

namespace requests {

/// A servo command without arguments: EStop, Reset, MachineOn, MachineOff, CycleStart, FeedHold,
/// Resume, Abort, ToolChanged, SpindleOff.
struct Servo {
  control::CommandKind kind = control::CommandKind::Abort;
};
struct SetMode {
  control::Mode mode = control::Mode::Manual;
};
/// Continuous jog at a signed speed (units/s); stops at the soft limit or on JogStop.
struct Jog {
  Axis axis = Axis::X;
  double velocity = 0;
};
/// Incremental jog by a signed distance at a speed (units, units/s).
struct JogBy {
  Axis axis = Axis::X;
  double distance = 0;
  double speed = 0;
};
/// Stops one axis's jog, or every axis's.
struct JogStop {
  std::optional<Axis> axis;
};
/// Homes one axis, or all of them in their sequences.
struct Home {
  std::optional<Axis> axis;
};
/// Seeks the axis' limit switch on the side of `direction` (+1 / −1): jogs to it, latches it
/// slowly and backs off onto its free side; where it tripped comes as a note and in the status
/// (ServoStatus::seek). Manual mode, idle.
struct SeekLimit {
  Axis axis = Axis::X;
  int direction = 1;
};
struct SetOverride {
  OverrideKind which = OverrideKind::Feed;
  double value = 1;
};
struct SetSwitch {
  SwitchKind which = SwitchKind::SingleBlock;
  bool on = false;
};
/// Manual spindle start (Manual mode).
struct SpindleOn {
  double rpm = 0;
  bool clockwise = true;
};
/// Manual coolant (Manual mode).
struct SetCoolant {
  control::Coolant which = control::Coolant::Flood;
  bool on = false;
};
/// Puts the handwheel on an axis (none: off every axis) with a step (units per count, one of the
/// profile's handwheel.steps).
struct SetHandwheel {
  std::optional<Axis> axis;
  double step = 0;
};
/// Opens a G-code file as the main program (Auto mode): preflight, then it waits for cycle start.
struct OpenFile {
  std::string path;
};
/// Opens a program built from canonical calls (generators, tests) as the main program.
struct OpenCanon {
  std::shared_ptr<const canon::Program> program;
  std::string name;
};
/// Runs one line of G-code (MDI mode).
struct Mdi {
  std::string line;
};
/// Runs a program of its own beside the main program, which stays open: a check routine, an
/// approach move, a recovery move. A file (`path`) or a canonical program. Auto mode, idle.
struct RunAuxiliary {
  std::string name;  ///< shown in status and events
  std::string path;
  std::shared_ptr<const canon::Program> program;
};
/// Runs the open program (a file; Auto mode, idle) from segment `segment` — the interpreter's
/// segment id, as in status and the path index — with the machine where it stands, on that
/// segment: the interpreter replays the program quietly up to it (ProgramSource::resume), so
/// modal state, offsets, compensation and the call stack are exact, and the program goes on
/// from there to its end. Power-fail resume and flame retrace use it.
struct ResumeProgram {
  canon::SegmentId segment = 0;
  /// Where the program started the first time (G91 at its head starts from there); unset:
  /// where the machine stood when the open program was last checked (opened or started).
  std::optional<Pose> program_start;
};
/// A request for a feature plugged into the controller (Controller::add_feature): `feature` names
/// it, `action` and `args` are the feature's own.
struct Feature {
  std::string feature;
  std::string action;
  std::any args;
};

/// Changes editable keys of the machine profile (config::editable_parameters: axis limits) while
/// nothing moves: the file's text edited key by key and loaded again by the profile loader, then
/// written back (atomically), the planner's limits and the move checks swapped, and the joints'
/// limits applied by the tick together. `who` names the one asking (for the event log).
/// With `conditions`, machining conditions are added (copies) or deleted as well; a delete is
/// refused while the open program selects that condition (its preflight with the new conditions,
/// whose message names the program's line).
struct EditProfile {
  std::vector<config::ProfileKeyEdit> edits;
  std::string who;
  std::vector<config::ConditionChange> conditions;
};

}  // namespace requests

using RequestBody =
    std::variant<requests::Servo, requests::SetMode, requests::Jog, requests::JogBy, requests::JogStop,
                 requests::Home, requests::SetOverride, requests::SetSwitch, requests::SpindleOn,
                 requests::SetCoolant, requests::OpenFile, requests::OpenCanon, requests::Mdi,
                 requests::RunAuxiliary, requests::Feature, requests::SetHandwheel, requests::ResumeProgram,
                 requests::EditProfile, requests::SeekLimit>;

/// A request with its typed body. Build one with the helpers.
struct Request {
  RequestBody body;

  /// A servo command without arguments (see requests::Servo).
  static Request simple(control::CommandKind k) { return {requests::Servo{k}}; }
  static Request set_mode(control::Mode m) { return {requests::SetMode{m}}; }
  static Request jog(Axis a, double velocity) { return {requests::Jog{a, velocity}}; }
  static Request jog_by(Axis a, double distance, double speed) { return {requests::JogBy{a, distance, speed}}; }
  static Request jog_stop(std::optional<Axis> a = {}) { return {requests::JogStop{a}}; }
  static Request home(std::optional<Axis> a = {}) { return {requests::Home{a}}; }
  static Request seek_limit(Axis a, int direction) { return {requests::SeekLimit{a, direction}}; }
  static Request feed_override(double v) { return {requests::SetOverride{OverrideKind::Feed, v}}; }
  static Request rapid_override(double v) { return {requests::SetOverride{OverrideKind::Rapid, v}}; }
  static Request spindle_override(double v) { return {requests::SetOverride{OverrideKind::Spindle, v}}; }
  static Request single_block(bool on) { return {requests::SetSwitch{SwitchKind::SingleBlock, on}}; }
  static Request optional_stop(bool on) { return {requests::SetSwitch{SwitchKind::OptionalStop, on}}; }
  static Request block_delete(bool on) { return {requests::SetSwitch{SwitchKind::BlockDelete, on}}; }
  static Request spindle_on(double rpm, bool clockwise) { return {requests::SpindleOn{rpm, clockwise}}; }
  static Request coolant(control::Coolant which, bool on) { return {requests::SetCoolant{which, on}}; }
  static Request handwheel(std::optional<Axis> a, double step) { return {requests::SetHandwheel{a, step}}; }
  static Request open(std::string path) { return {requests::OpenFile{std::move(path)}}; }
  static Request open(std::shared_ptr<const canon::Program> p, std::string name) {
    return {requests::OpenCanon{std::move(p), std::move(name)}};
  }
  static Request mdi(std::string line) { return {requests::Mdi{std::move(line)}}; }
  static Request run_auxiliary(std::string name, std::string path) {
    return {requests::RunAuxiliary{std::move(name), std::move(path), nullptr}};
  }
  static Request run_auxiliary(std::string name, std::shared_ptr<const canon::Program> p) {
    return {requests::RunAuxiliary{std::move(name), {}, std::move(p)}};
  }
  static Request resume(canon::SegmentId segment, std::optional<Pose> program_start = {}) {
    return {requests::ResumeProgram{segment, program_start}};
  }
  static Request edit_profile(std::vector<config::ProfileKeyEdit> edits, std::string who = {}) {
    return {requests::EditProfile{std::move(edits), std::move(who), {}}};
  }
  static Request change_conditions(std::vector<config::ConditionChange> changes, std::string who = {}) {
    return {requests::EditProfile{{}, std::move(who), std::move(changes)}};
  }
  static Request feature(std::string feature, std::string action, std::any args = {}) {
    return {requests::Feature{std::move(feature), std::move(action), std::move(args)}};
  }

  /// A short name for logs and audits ("jog", "open", "mdi", "machine-on", …). Any thread.
  std::string name() const;
};

/// The servo command a request stands for (nothing for the controller's own requests). Any thread.
std::optional<control::Command> to_command(const Request& r);

/// The urgent lane (docs/controller.md, "Stops never wait"): an e-stop, machine off, abort, feed
/// hold, jog stop, spindle off, coolant off or an override goes from the thread that submits it
/// straight to the tick (ServoChannels::urgent), whatever the controller is busy with. Any thread.
bool takes_urgent_lane(const Request& r);
/// A stop (e-stop, machine off, abort, feed hold): requests sent before it that would start
/// something are dropped once it has acted (control.superseded). Any thread.
bool is_stop(const Request& r);
/// A halt (e-stop, machine off, abort): it also cancels the controller's long work (a preflight,
/// a replay) for requests sent before it. Any thread.
bool is_halt(const Request& r);

}  // namespace opencnc::controller
