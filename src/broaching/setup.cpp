// SPDX-License-Identifier: GPL-3.0-or-later
// Broaching on a machine: the coupling codes and pass, the load guard's and the coupling's words,
// the breakpoint journal and its state, added to the hub through its extension points.
#include "opencnc/broaching/setup.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/broaching/coupling_codes.hpp"
#include "opencnc/broaching/coupling_pass.hpp"
#include "texts.hpp"

namespace opencnc::broaching {

namespace {

/// M171-M175 on top of the dialect's modules, and the coupling pass over every program's moves.
class Coupling final : public controller::SourcePart {
 public:
  explicit Coupling(const broaching::CoupledAxes& axes) : axes_(axes) {}
  std::shared_ptr<const gcode::Extensions> modules(
      gcode::Dialect, std::shared_ptr<const gcode::Extensions> base) const override {
    auto ext = std::make_shared<gcode::Extensions>(*base);
    gcode::add_coupling_codes(*ext);
    return ext;
  }
  std::unique_ptr<controller::MovePass> pass() const override {
    return std::make_unique<broaching::CouplingPass>(axes_);
  }

 private:
  broaching::CoupledAxes axes_;
};

const char* phase_name(recovery::RecoveryPhase p) {
  static constexpr const char* names[] = {"none",       "opening", "running-in", "resuming",
                                          "retracting", "done",    "failed"};
  return names[static_cast<std::size_t>(p)];
}

/// The journal's state for a front end (docs/api.md, "features"): the record written last, the
/// recovery's phase, what a dialog may offer and the resume's values it offers.
class JournalState final : public controller::FeatureState {
 public:
  JournalState(std::shared_ptr<recovery::BreakpointJournal> journal, const config::MachineProfile& profile)
      : journal_(std::move(journal)), profile_(profile) {}
  std::string state_key() const override { return "journal"; }
  std::string state_json(const controller::ControllerStatus& s) override {
    using nlohmann::json;
    json r = nullptr;
    if (const std::optional<recovery::BreakpointRecord> rec = journal_->last_written()) {
      json actual = json::object();
      for (const config::AxisProfile& a : profile_.axes)
        actual[std::string(1, letter(a.axis))] = rec->actual[index(a.axis)];
      r = {{"valid", rec->valid},
           {"stage", recovery::to_string(rec->stage)},
           {"program", rec->program_path},
           {"file", rec->source_file},
           {"line", rec->line},
           {"segment", rec->segment},
           {"segment_offset_mm", rec->segment_offset_mm},
           {"move_remaining_mm", rec->move_remaining_mm},
           {"actual", actual},
           {"tool", rec->tool},
           {"spindle_rpm", rec->spindle_rpm},
           {"coupled", rec->coupling.kind != 0},
           {"signal_time_s", rec->signal_time_s},
           {"summary", recovery::describe(*rec)}};
    }
    const bool valid = !r.is_null() && r["valid"].get<bool>();
    const config::PowerProfile& p = profile_.power;
    return json{{"record", r},
                {"phase", phase_name(journal_->phase())},
                {"recovery_error", journal_->recovery_error()},
                {"write_error", journal_->last_error()},
                // What the dialog may offer: resume needs a record completed at rest, retract a
                // law that held; the machine must be on and idle for either to start.
                {"can_resume", valid && r["stage"] == "at-rest"},
                {"can_retract", valid && r["coupled"].get<bool>()},
                // The resume's values the dialog offers (the operator may change them).
                {"resume_defaults",
                 {{"tolerance_mm", p.resume_tolerance_mm},
                  {"tolerance_deg", p.resume_tolerance_deg},
                  {"run_in_mm", p.resume_run_in_mm},
                  {"run_in_speed_mm_min", p.resume_run_in_speed_mm_min}}},
                {"mains_ok", s.servo.mains_ok && !s.servo.on_battery}}
        .dump();
  }

 private:
  std::shared_ptr<recovery::BreakpointJournal> journal_;
  config::MachineProfile profile_;
};

}  // namespace

bool setup(const config::MachineProfile& profile, controller::MachineSetup& host) {
  const broaching::CoupledAxes axes = broaching::coupled_axes(profile);
  if (axes.any()) host.add_source_part(std::make_shared<Coupling>(axes));
  if (axes.any() || profile.broaching.present) host.add_texts(std::make_shared<Texts>());
  // The journal follows the trace (it builds its record from the interrupted move) and the status.
  const std::string* dir = host.setting("journal");
  if (profile.power.monitor && dir != nullptr && !dir->empty()) {
    std::string error;
    auto journal = recovery::BreakpointJournal::open(*dir, host.make_source(), &error);
    if (!journal) {
      host.diagnostics().error(*dir, 0, 0, fmt::format("the breakpoint journal: {}", error),
                               "setting.journal");
      return false;
    }
    host.add_feature(journal, controller::ObserverOptions{profile.servo_period_s, true});
    host.add_state(std::make_shared<JournalState>(journal, profile));
  }
  return true;
}

}  // namespace opencnc::broaching
