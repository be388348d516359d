// SPDX-License-Identifier: GPL-3.0-or-later
// The EDM's part of `opencnc run`: a short in the simulated gap (--inject edm-short), the worn
// electrode replaced mid-job (--electrode-change), the burn's report with the simulated work's
// figures (docs/edm.md).
#include <fmt/format.h>

#include "electrode_change.hpp"
#include "opencnc/edm/edm_recorder.hpp"
#include "opencnc/edm/electrode_setting.hpp"
#include "opencnc/machine/sim_machine.hpp"
#include "run_features_parts.hpp"

namespace opencnc::cli {

namespace {

/// The simulated spark gap's ground truth at the end of a run in virtual time: what a real
/// machine shows only when the work is measured.
struct SimFigures {
  double cavity_oversize_mm = 0;  ///< the widest cavity's oversize per side beyond the electrode
  double electrode_wear_mm = 0;   ///< the most length an electrode lost
  double cavity_depth_mm = 0;     ///< the deepest front below the work's surface
};

class EdmRun final : public RunFeature {
 public:
  void add_options(CLI::App& run) override {
    run.add_option(
           "--electrode-change", changes_text_,
           "Script the EDM operator who replaces a worn electrode (virtual time, a simulated reference "
           "sphere): at AT_SECONDS into the run feed hold and abort, lift the electrode 10 mm along the "
           "tool axis, put in a new one whose true offsets are X,Y,Z (mm), measure it on the sphere, store "
           "it (in a copy of the tool table) and resume where the job stopped (repeatable; the report "
           "lists them as `electrode_changes`; docs/edm.md)")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
        ->check(CLI::Validator(
            [](const std::string& s) {
              return parse_electrode_change(s) ? std::string()
                                               : "expected AT_SECONDS:X,Y,Z (seconds into the run, mm), e.g. "
                                                 "20:0.02,-0.01,0.05";
            },
            "AT_SECONDS:X,Y,Z"));
  }
  std::vector<InjectionForm> injections() const override {
    return {{"edm-short@SECONDS", "a short in the simulated EDM gap", ""}};
  }
  bool parse_injection(const std::string& text, bool& ok) override {
    if (text.rfind("edm-short@", 0) != 0) return false;
    const char* end = nullptr;
    short_s_ = injection_number(text.c_str() + 10, '\0', end);
    ok = short_s_ >= 0;
    return true;
  }
  bool check(const config::MachineProfile* profile, SessionOptions& session) override {
    if (short_s_ >= 0 && profile && !profile->edm.sim.present) {
      fmt::print(stderr, "error: --inject edm-short needs a simulated spark gap ([edm.sim] in {})\n",
                 session.machine);
      return false;
    }
    sim_gap_ = profile && profile->edm.sim.present;
    if (changes_text_.empty()) return true;
    if (session.realtime || session.hal) {
      fmt::print(stderr,
                 "error: --electrode-change works in virtual time only (not with --realtime or --hal)\n");
      return false;
    }
    if (profile && !(profile->probe.reference_sphere.present && profile->probe.reference_sphere.sim)) {
      fmt::print(
          stderr,
          "error: --electrode-change needs a simulated reference sphere ([probe.reference_sphere.sim] in "
          "{})\n",
          session.machine);
      return false;
    }
    session.tool_table_in_memory = true;  // the simulated electrodes' offsets stay out of the table file
    for (const std::string& text : changes_text_) changes_.push_back(*parse_electrode_change(text));
    return true;
  }
  bool set_up(controller::MachineSetup& machine) override {
    for (const auto& [observer, options] : machine.observers())  // the burn's report section
      if (auto e = std::dynamic_pointer_cast<edm::EdmRecorder>(observer)) recorder_ = e;
    if (changes_.empty()) return true;
    auto electrode = std::dynamic_pointer_cast<edm::ElectrodeSetting>(machine.feature("electrode"));
    if (!electrode) {
      fmt::print(stderr, "error: --electrode-change: the machine has no tool table for the electrodes\n");
      return false;
    }
    const config::MachineProfile& p = machine.profile();
    const Axis axis = p.edm.present ? static_cast<Axis>(p.edm.config.tool_axis) : Axis::Z;
    const config::AxisProfile* a = p.find(axis);
    const double lift = p.edm.present ? 10.0 * p.edm.config.lift_direction : 10.0;
    changer_.emplace(changes_, electrode, axis, lift, a != nullptr ? a->min_limit : -1e9,
                     a != nullptr ? a->max_limit : 1e9);
    return true;
  }
  void tick(controller::Controller& c, const controller::ControllerStatus& st,
            machine::SimMachine* sim) override {
    if (short_s_ >= 0 && !shorted_ && sim != nullptr && st.servo.time_s >= short_s_) {
      sim->inject_edm_short();
      shorted_ = true;
    }
    if (changer_) changer_->tick(c, st, sim);
  }
  bool goes_on(const controller::ControllerEvent& e) const override {
    return changer_ && changer_->goes_on(e);
  }
  void finished(machine::SimMachine* sim) override {
    if (sim == nullptr || !sim_gap_) return;
    const machine::SimEdmProcess& e = sim->edm();
    sim_ = SimFigures{e.cavity_oversize_max_mm(), e.electrode_wear_max_mm(), e.depth_max_mm()};
  }
  bool report(nlohmann::json& j) override {
    if (recorder_) {
      fmt::print("{}", recorder_->report_text());
      nlohmann::json e = nlohmann::json::parse(recorder_->report_json());
      if (sim_) {
        fmt::print(
            "edm simulated work  cavity {:.4f} mm over the electrode a side, {:.4f} mm deep; electrode wear "
            "up "
            "to {:.4f} mm\n",
            sim_->cavity_oversize_mm, sim_->cavity_depth_mm, sim_->electrode_wear_mm);
        e["cavity_oversize_mm"] = sim_->cavity_oversize_mm;
        e["electrode_wear_mm"] = sim_->electrode_wear_mm;
        e["cavity_depth_mm"] = sim_->cavity_depth_mm;
      }
      j[recorder_->report_key()] = std::move(e);
    }
    if (changer_) {
      for (const ElectrodeChangeRecord& x : changer_->records()) {
        const edm::ElectrodeResult& m = x.measured;
        fmt::print(
            "electrode change    at {:.3f} s, tool {}, segment {}: measured X{:.4f} Y{:.4f} Z{:.4f} (was "
            "X{:.4f} Y{:.4f} Z{:.4f}), {}\n",
            x.at_s, x.tool, x.segment, m.offset[0], m.offset[1], m.offset[2], m.previous[0], m.previous[1],
            m.previous[2], x.resumed ? "resumed" : "not resumed");
      }
      j["electrode_changes"] = changer_->json();
    }
    return true;
  }

 private:
  std::vector<std::string> changes_text_;
  std::vector<ElectrodeChangeAt> changes_;
  std::optional<ElectrodeChangeScript> changer_;
  double short_s_ = -1;
  bool shorted_ = false, sim_gap_ = false;
  std::shared_ptr<edm::EdmRecorder> recorder_;
  std::optional<SimFigures> sim_;
};

}  // namespace

std::unique_ptr<RunFeature> edm_run() {
  return std::make_unique<EdmRun>();
}

}  // namespace opencnc::cli
