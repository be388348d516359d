// SPDX-License-Identifier: GPL-3.0-or-later
// The features a profile calls for, installed on the server's controller, and the board that
// turns their state into JSON on the controller's thread for the status and the stream.
#include "opencnc/hmi/machine_features.hpp"

#include <fmt/format.h>

#include "opencnc/controller/electrode_setting.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/run_from_line.hpp"
#include "opencnc/recovery/breakpoint_journal.hpp"
#include "opencnc/recovery/retrace.hpp"
#include "opencnc/toolguard/tool_guard.hpp"

namespace opencnc::hmi {

using nlohmann::json;

namespace {

const char* phase_name(recovery::RecoveryPhase p) {
  static constexpr const char* names[] = {"none",       "opening", "running-in", "resuming",
                                          "retracting", "done",    "failed"};
  return names[static_cast<std::size_t>(p)];
}

json pose_json(const Pose& p, const config::MachineProfile& profile) {
  json j = json::object();
  for (const config::AxisProfile& a : profile.axes) j[std::string(1, letter(a.axis))] = p[index(a.axis)];
  return j;
}

json vec3_json(const Vec3& v) {
  return json::array({v[0], v[1], v[2]});
}

}  // namespace

/// Follows the status on the controller's thread and stores the features' state for the server.
class MachineFeatures::Board final : public control::ControllerObserver {
 public:
  explicit Board(MachineFeatures& owner) : owner_(owner) {}
  void on_status(const control::ControllerStatus& s) override {
    json j = owner_.snapshot(s);
    if (owner_.profile_.edm.present) j["edm"] = edm_depth(s.servo);
    std::lock_guard lock(owner_.mutex_);
    owner_.state_ = std::move(j);
  }

 private:
  /// The depth burnt as the EDM report counts it (docs/edm.md, `depth_mm`): the electrode's
  /// travel into the work along the tool axis from the burn's first discharge; a burn runs from
  /// a condition's selection to M181. At the status rate, so a depth the electrode held between
  /// two samples only is missed (the report's, from every period, is exact).
  json edm_depth(const control::ServoStatus& v) {
    const machine::EdmConfig& c = owner_.profile_.edm.config;
    const double along = v.actual[static_cast<std::size_t>(c.tool_axis)];
    if (!v.edm.on) {
      burning_ = false;
    } else if (!burning_ && v.edm.gap_state != machine::GapState::Open) {
      burning_ = true;
      start_ = along;
      depth_mm_ = 0;
    }
    if (burning_) depth_mm_ = std::max(depth_mm_, (start_ - along) * c.lift_direction);
    return {{"depth_mm", depth_mm_}, {"burning", burning_}};
  }

  MachineFeatures& owner_;
  bool burning_ = false;
  double start_ = 0, depth_mm_ = 0;
};

std::unique_ptr<MachineFeatures> MachineFeatures::create(const config::MachineProfile& profile,
                                                         const FeatureOptions& options, Diagnostics& diags) {
  std::unique_ptr<MachineFeatures> f(new MachineFeatures);
  f->profile_ = profile;
  // With [tool_guard] the tool store is the interpreter's table and the guard is a feature.
  std::optional<toolguard::Setup> setup = toolguard::setup(profile, diags);
  if (!setup) return nullptr;
  f->source_ = setup->source;
  f->store_ = setup->store;
  f->guard_ = setup->feature;
  auto add = [&f](std::shared_ptr<control::Feature> feature) {
    f->names_.emplace_back(feature->name());
    f->features_.push_back(std::move(feature));
  };
  if (f->guard_) add(f->guard_);
  if (profile.power.monitor && !options.journal_dir.empty()) {
    std::string error;
    f->journal_ = recovery::BreakpointJournal::open(
        options.journal_dir, control::GcodeProgramSource::create(profile, diags), &error);
    if (!f->journal_) {
      diags.error(options.journal_dir, 0, 0, fmt::format("the breakpoint journal: {}", error), "hmi.journal");
      return nullptr;
    }
    add(f->journal_);
  }
  if (profile.probe.reference_sphere.present && f->source_->tools()) {
    f->electrode_ = std::make_shared<control::ElectrodeSetting>(f->source_->tools(), profile);
    add(f->electrode_);
  }
  if (profile.cutting.present) {
    f->retrace_ = std::make_shared<recovery::RetraceFeature>(
        control::GcodeProgramSource::create(profile, diags), profile);
    add(f->retrace_);
  }
  // Run from line scans with a program source of its own (the controller's is the controller's),
  // reading the controller's tool table (a scan's G10 L1 writes only a copy of its own).
  std::shared_ptr<control::RunFromLineFeature> from_line =
      control::RunFromLineFeature::create(profile, f->source_->tools(), diags);
  if (!from_line) return nullptr;
  add(from_line);
  f->state_ = {{"installed", f->names_}};
  return f;
}

MachineFeatures::~MachineFeatures() = default;

void MachineFeatures::install(control::Controller& controller) {
  // Every feature follows the status every period; the journal and the electrode setting also
  // the trace (the journal builds its record from it, the electrode follows the segment).
  const double period = profile_.servo_period_s;
  for (const auto& f : features_) {
    const bool trace = f == journal_ || f == electrode_;
    controller.add_feature(f, control::ObserverOptions{period, trace});
  }
  // Attached after the features: it sees their state of the same period. 50 Hz is above the
  // stream's default rate.
  controller.attach(std::make_shared<Board>(*this), control::ObserverOptions{std::max(period, 0.02), false});
}

json MachineFeatures::status() const {
  std::lock_guard lock(mutex_);
  return state_;
}

json MachineFeatures::snapshot(const control::ControllerStatus& s) {
  json j{{"installed", names_}};
  if (journal_) {
    json r = nullptr;
    if (const std::optional<recovery::BreakpointRecord> rec = journal_->last_written()) {
      r = {{"valid", rec->valid},
           {"stage", recovery::to_string(rec->stage)},
           {"program", rec->program_path},
           {"file", rec->source_file},
           {"line", rec->line},
           {"segment", rec->segment},
           {"segment_offset_mm", rec->segment_offset_mm},
           {"move_remaining_mm", rec->move_remaining_mm},
           {"actual", pose_json(rec->actual, profile_)},
           {"tool", rec->tool},
           {"spindle_rpm", rec->spindle_rpm},
           {"coupled", rec->coupling.kind != 0},
           {"signal_time_s", rec->signal_time_s},
           {"summary", recovery::describe(*rec)}};
    }
    const bool valid = !r.is_null() && r["valid"].get<bool>();
    j["journal"] = {{"record", r},
                    {"phase", phase_name(journal_->phase())},
                    {"recovery_error", journal_->recovery_error()},
                    {"write_error", journal_->last_error()},
                    // What the dialog may offer: resume needs a record completed at rest, retract
                    // a law that held; the machine must be on and idle for either to start.
                    {"can_resume", valid && r["stage"] == "at-rest"},
                    {"can_retract", valid && r["coupled"].get<bool>()},
                    // The resume's values the dialog offers (the operator may change them).
                    {"resume_defaults",
                     {{"tolerance_mm", profile_.power.resume_tolerance_mm},
                      {"tolerance_deg", profile_.power.resume_tolerance_deg},
                      {"run_in_mm", profile_.power.resume_run_in_mm},
                      {"run_in_speed_mm_min", profile_.power.resume_run_in_speed_mm_min}}},
                    {"mains_ok", s.servo.mains_ok && !s.servo.on_battery}};
  }
  if (retrace_) {
    json last = nullptr;
    const std::vector<recovery::RetraceRecord> records = retrace_->records();
    if (!records.empty()) {
      const recovery::RetraceRecord& r = records.back();
      last = {{"a", r.a_known ? vec3_json(r.a) : json(nullptr)},
              {"b", vec3_json(r.b)},
              {"c", vec3_json(r.c)},
              {"line", r.line},
              {"segment", r.segment},
              {"distance_mm", r.distance_mm},
              {"candidates", r.candidates}};
    }
    j["retrace"] = {
        {"phase", recovery::to_string(retrace_->phase())}, {"retraces", records.size()}, {"last", last}};
  }
  if (electrode_) {
    json last = nullptr;
    if (const std::optional<control::ElectrodeResult> r = electrode_->last()) {
      last = {{"ok", r->ok},
              {"code", r->code},
              {"message", r->message},
              {"tool", r->tool},
              {"touches", r->names.size()},
              {"previous", vec3_json(r->previous)},
              {"offset", vec3_json(r->offset)},
              {"rms_residual_mm", r->rms_residual_mm},
              {"max_residual_mm", r->max_residual_mm},
              {"written", r->written}};
    }
    json b_axis = nullptr;
    if (const std::optional<control::BAxisResult> c = electrode_->last_b_axis()) {
      b_axis = {{"ok", c->ok},
                {"code", c->code},
                {"message", c->message},
                {"angles_deg", c->angles_deg},
                {"b_axis", c->fit.axis.crossing},
                {"b_axis_direction", vec3_json(c->fit.axis.direction)},
                {"max_residual_mm", c->fit.max_residual_mm}};
    }
    j["electrode"] = {{"phase", control::to_string(electrode_->phase())},
                      {"last", last},
                      {"b_axis", b_axis},
                      {"stopped_program", electrode_->stop().has_value()}};
  }
  if (guard_) j["tool_guard"] = tool_guard_state(s);
  return j;
}

// While the guard holds the program at a tool change (the controller's wait text names the
// feature that holds), the differences of the whole live table from the backup, for the dialog.
// The check reads the store (SQLite): it runs once when the hold begins and again only when the
// store has changed, not at every status.
json MachineFeatures::tool_guard_state(const control::ControllerStatus& s) {
  const bool holding = s.wait_text.find("the tool-guard ") != std::string::npos;
  if (!holding) {
    guard_holding_ = false;
    guard_report_ = nullptr;
  } else if (!guard_holding_ || store_->changes() != guard_checked_) {
    guard_holding_ = true;
    guard_checked_ = store_->changes();
    const toolguard::CheckResult r = toolguard::check(*store_, toolguard::tolerances(profile_.tool_guard));
    json lines = json::array(), tools = json::array();
    for (const tools::Difference& d : r.differences) {
      lines.push_back(d.text());
      tools.push_back(d.tool);  // the dialog lists the program's tools first
    }
    guard_report_ = {
        {"ok", r.ok()},
        {"error", r.error},
        {"backup", r.backup ? json{{"id", r.backup->id}, {"taken", r.backup->taken_utc}} : json(nullptr)},
        {"differences", lines},
        {"difference_tools", tools},
        {"report", r.report()}};
  }
  return {{"store", profile_.tool_guard.store}, {"holding", holding}, {"check", guard_report_}};
}

}  // namespace opencnc::hmi
