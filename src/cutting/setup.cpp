// SPDX-License-Identifier: GPL-3.0-or-later
// Plasma cutting on a machine: codes, holes pass, texts, recorder and state through the hub's
// extension points.
#include "opencnc/cutting/setup.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "opencnc/cutting/cut_chart.hpp"
#include "opencnc/cutting/cutting_recorder.hpp"
#include "opencnc/cutting/hole_pass.hpp"
#include "opencnc/cutting/torch_codes.hpp"

namespace opencnc::cutting {

namespace {

const char* phase_name(control::TorchPhase p) {
  switch (p) {
    case control::TorchPhase::Off:
      return "off";
    case control::TorchPhase::Probing:
      return "probing";
    case control::TorchPhase::ToPierce:
      return "to-pierce";
    case control::TorchPhase::Igniting:
      return "igniting";
    case control::TorchPhase::Piercing:
      return "piercing";
    case control::TorchPhase::Puddle:
      return "puddle-jump";
    case control::TorchPhase::ToCut:
      return "to-cut";
    case control::TorchPhase::Cutting:
      return "cutting";
    case control::TorchPhase::Retracting:
      return "retracting";
    case control::TorchPhase::Paused:
      return "paused";
    case control::TorchPhase::Failed:
      return "failed";
    case control::TorchPhase::Preheating:
      return "preheating";
  }
  return "?";
}

const char* thc_name(control::ThcState s) {
  switch (s) {
    case control::ThcState::Off:
      return "off";
    case control::ThcState::Waiting:
      return "waiting";
    case control::ThcState::Sampling:
      return "sampling";
    case control::ThcState::Active:
      return "active";
    case control::ThcState::CornerLock:
      return "corner-lock";
    case control::ThcState::AntiDive:
      return "anti-dive";
    case control::ThcState::VoidLock:
      return "void-lock";
    case control::ThcState::ProgramLock:
      return "program-lock";
  }
  return "?";
}

/// The torch's codes, and the holes pass when the profile sets a hole diameter.
class Part final : public controller::SourcePart {
 public:
  explicit Part(const config::PlasmaHoles& holes) : holes_(holes) {}
  std::shared_ptr<const gcode::Extensions> modules(
      gcode::Dialect dialect, std::shared_ptr<const gcode::Extensions> base) const override {
    return gcode::torch_extensions(dialect, std::move(base));
  }
  std::unique_ptr<controller::CallPass> call_pass() const override {
    if (holes_.diameter_mm <= 0) return nullptr;
    return std::make_unique<HolePass>(holes_);
  }

 private:
  config::PlasmaHoles holes_;
};

/// The torch stage's events in words.
class Texts final : public controller::EventTexts {
 public:
  std::optional<controller::EventNote> event_note(const control::ServoEvent& e,
                                                  const config::MachineProfile& p,
                                                  const control::ServoConfig&) const override {
    if (e.kind != control::EventKind::Torch) return std::nullopt;
    switch (static_cast<control::TorchEvent>(e.action)) {
      case control::TorchEvent::ArcLost:
        return controller::EventNote{
            Severity::Warning, "control.torch.arc-lost",
            "plasma: the arc was lost while cutting; the torch is off and the run held "
            "there: resume to find the plate and pierce again where the torch stands, "
            "or retrace to another point of the path"};
      case control::TorchEvent::StartFailed:
        return controller::EventNote{
            Severity::Warning, "control.torch.start-failed",
            fmt::format("plasma: no arc-OK within {} s (start {} of {} in a row failed); trying again",
                        p.plasma.config.arc_ok_timeout_s, e.value, p.plasma.config.max_starts)};
      case control::TorchEvent::StartsExhausted:
        return controller::EventNote{
            Severity::Error, "control.torch.starts-exhausted",
            fmt::format("plasma: {} starts in a row without arc-OK; the run is held (check the gas, the "
                        "consumables, the work clamp), resume to try again",
                        e.value)};
      case control::TorchEvent::Breakaway:
        return controller::EventNote{
            Severity::Error, "control.torch.breakaway",
            fmt::format("{}: the torch's breakaway switch tripped (it hit a tipped part or the plate); the "
                        "torch is off and the run held: seat the torch, then resume to pierce again where it "
                        "stands, or retrace",
                        p.plasma.config.oxy_fuel() ? "oxy-fuel" : "plasma")};
      case control::TorchEvent::FloatTripped:
        return controller::EventNote{
            Severity::Error, "control.torch.float-tripped",
            "plasma: the float switch tripped while the torch burned (it touched the plate); the torch is "
            "off "
            "and the run held: resume to find the plate and pierce again where it stands, or retrace"};
      case control::TorchEvent::PreheatWaits:
        return controller::EventNote{Severity::Note, "control.torch.preheat-waits",
                                     "oxy-fuel: the flame preheats the plate; start the cut (Start cut) when "
                                     "the steel glows at the kerf's start"};
      case control::TorchEvent::CutStarted:
        return controller::EventNote{
            Severity::Note, "control.torch.cut-started",
            fmt::format("oxy-fuel: preheated {:.1f} s; cutting oxygen on, piercing", e.value)};
      case control::TorchEvent::PlateNotFound:
        return controller::EventNote{
            Severity::Error, "control.torch.no-plate",
            fmt::format("{}: the torch went {} mm below the programmed height without its {} (no plate?); "
                        "the run is held",
                        p.plasma.config.oxy_fuel() ? "oxy-fuel" : "plasma", p.plasma.config.probe_travel_mm,
                        p.plasma.config.oxy_fuel() ? "height sensor reading the plate"
                        : p.plasma.config.sensor == machine::PlateSensor::Float ? "float switch"
                                                                                : "ohmic contact")};
    }
    return std::nullopt;
  }
};

/// The torch for a front end's cutting panel: phase, height control, arc voltage, offset, I/O.
class State final : public controller::FeatureState {
 public:
  std::string state_key() const override { return "cutting"; }
  std::string state_json(const controller::ControllerStatus& s) override {
    const control::TorchStatus& t = s.servo.torch;
    // Why the torch stage holds the run, for the HMI's dialog: a breakaway, a float trip or an arc
    // lost since the torch was last outside a pause, or a failed start (no arc-OK after its
    // retries, no plate).
    const bool paused = t.phase == control::TorchPhase::Paused;
    if (!paused && t.phase != control::TorchPhase::Failed) {
      losses_ = t.arc_losses;
      breakaways_ = t.breakaways;
      float_trips_ = t.float_trips;
    }
    const char* reason = t.phase == control::TorchPhase::Failed   ? "failed"
                         : paused && t.breakaways > breakaways_   ? "breakaway"
                         : paused && t.float_trips > float_trips_ ? "float"
                         : paused && t.arc_losses > losses_       ? "arc-lost"
                                                                  : "";
    return nlohmann::json{{"phase", phase_name(t.phase)},
                          {"thc", thc_name(t.thc)},
                          {"torch_on", t.torch_on},
                          {"arc_ok", t.arc_ok},
                          {"sensor", t.sensor},
                          {"arc_voltage_v", t.arc_voltage_v},
                          {"target_voltage_v", t.target_voltage_v},
                          {"thc_offset_mm", t.thc_offset_mm},
                          {"correction_mm", t.correction_mm},
                          {"plate_z_mm", t.plate_z_mm},
                          {"pierces", t.pierces},
                          {"arc_losses", t.arc_losses},
                          {"hold_reason", reason},
                          {"process", t.oxy_fuel ? "oxy-fuel" : "plasma"},
                          {"cut_oxygen", t.cut_oxygen},
                          {"waiting_start", t.waiting_start},
                          {"sensor_height_mm", t.sensor_height_mm},
                          {"preheat_s", t.preheat_s},
                          {"preheats", t.preheats}}
        .dump();
  }

 private:
  // The torch's counts when it was last neither paused nor failed.
  std::uint32_t losses_ = 0, breakaways_ = 0, float_trips_ = 0;
};

}  // namespace

bool setup(const config::MachineProfile& profile, controller::MachineSetup& host) {
  if (!profile.plasma.present) return true;
  host.add_source_part(std::make_shared<Part>(profile.plasma.holes));
  if (!setup_cut_chart(profile, host)) return false;  // M194, G41/G42 by the kerf (after the torch's codes)
  host.add_texts(std::make_shared<Texts>());
  host.add_state(std::make_shared<State>());
  if (host.reports())
    host.add_observer(
        std::make_shared<CuttingRecorder>(profile.plasma.config, profile.plasma.sim, profile.servo_period_s),
        controller::ObserverOptions{0, true});
  return true;
}

}  // namespace opencnc::cutting
