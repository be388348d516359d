// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc electrode-set`: measure an electrode against the reference sphere on the simulated
// machine and store its offsets in the tool table (docs/electrode-setting.md).
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/electrode_setting.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"

namespace opencnc::cli {

namespace {

struct ElectrodeOptions {
  std::string profile;
  std::vector<std::string> sets;
  int tool = 0;
  std::vector<double> sim_electrode;  ///< X Y Z: the simulated electrode's true offsets
  bool write = false;
  bool json = false;
  std::string report;
};

/// Ten minutes of machine time: far more than the touches of any sphere take.
constexpr std::uint64_t kElectrodeMaxTicks = 600'000;

double electrode_um(double mm) {
  return std::round(mm * 1e4) / 10;  // µm to a tenth
}

nlohmann::json json_point(const control::Point3& p) {
  return {p[0], p[1], p[2]};
}

nlohmann::json result_json(const control::ElectrodeResult& r) {
  nlohmann::json touches = nlohmann::json::array();
  for (std::size_t i = 0; i < r.touched.size(); ++i)
    touches.push_back({{"from", i < r.names.size() ? r.names[i] : ""}, {"at", json_point(r.touched[i])}});
  nlohmann::json j = {{"ok", r.ok},     {"code", r.code},     {"message", r.message},
                      {"tool", r.tool}, {"touches", touches}, {"previous", json_point(r.previous)}};
  if (r.touched.size() == r.names.size() && r.code != "electrode.missing-touch" &&
      r.code != "electrode.stopped") {
    j["offset"] = json_point(r.offset);
    j["length_mm"] = r.offset[2];
    j["centre"] = json_point(r.centre);
    j["rms_residual_um"] = electrode_um(r.rms_residual_mm);
    j["max_residual_um"] = electrode_um(r.max_residual_mm);
  }
  return j;
}

void print_electrode(const control::ElectrodeResult& r) {
  for (std::size_t i = 0; i < r.touched.size(); ++i)
    fmt::print("  touch {:<5} X{:.4f} Y{:.4f} Z{:.4f}\n", i < r.names.size() ? r.names[i] : "",
               r.touched[i][0], r.touched[i][1], r.touched[i][2]);
  if (!r.ok) return;
  fmt::print("tool {}: X {:.4f}  Y {:.4f}  Z (length) {:.4f} mm; before X {:.4f}  Y {:.4f}  Z {:.4f}\n",
             r.tool, r.offset[0], r.offset[1], r.offset[2], r.previous[0], r.previous[1], r.previous[2]);
  fmt::print("fit: residual {:.1f} µm rms, {:.1f} µm at most\n", 1000 * r.rms_residual_mm,
             1000 * r.max_residual_mm);
}

/// The profile's tool table: the file itself with --write (every change written back), else a
/// copy in memory.
std::shared_ptr<tools::ToolTableService> electrode_tool_table(const config::MachineProfile& p, bool write) {
  Diagnostics d;
  std::shared_ptr<tools::ToolTableService> t;
  if (write) {
    t = tools::FileToolTable::open(p.interpreter.tool_table, d);
  } else if (auto table = tools::ToolTable::load(p.interpreter.tool_table, d)) {
    t = std::make_shared<tools::MemoryToolTable>(std::move(*table));
  }
  for (const Diagnostic& i : d.items()) fmt::print(stderr, "{} [{}]\n", i.format(), i.code);
  return d.has_errors() ? nullptr : t;
}

bool machine_ready(control::SimRig& rig) {
  using control::CommandKind;
  using control::Request;
  const auto must = [&](Request r) {
    const control::Outcome o = rig.request(std::move(r), 100000);
    if (!o.accepted) fmt::print(stderr, "error: the machine refused: {}\n", o.message);
    return o.accepted;
  };
  if (!must(Request::simple(CommandKind::MachineOn))) return false;
  if (!rig.controller().servo_config().homing_required) return true;
  if (!must(Request::set_mode(control::Mode::Manual)) || !must(Request::home())) return false;
  return rig.run_until(
      [&] { return rig.status().servo.all_homed && rig.status().servo.state == control::State::Idle; },
      kElectrodeMaxTicks);
}

int electrode_set(const ElectrodeOptions& o) {
  const config::ProfileLoad load = config::load_profile(o.profile, o.sets);
  for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{} [{}]\n", d.format(), d.code);
  if (!load.ok()) return load.diagnostics.items()[0].code == "config.file" ? kExitUsage : kExitProgram;
  const config::MachineProfile& profile = *load.profile;
  const config::ReferenceSphereProfile& sphere = profile.probe.reference_sphere;
  if (!sphere.present || !sphere.sim) {
    fmt::print(stderr, "error: {} has no {}: nothing to touch\n", o.profile,
               sphere.present ? "[probe.reference_sphere.sim] (the simulated machine's sphere)"
                              : "[probe.reference_sphere]");
    return kExitUsage;
  }
  if (profile.interpreter.tool_table.empty()) {
    fmt::print(stderr, "error: {} names no tool table ([interpreter] tool_table)\n", o.profile);
    return kExitUsage;
  }
  std::unique_ptr<OutputFile> report;
  if (!o.report.empty()) {
    const NamedPath inputs[] = {{"the profile", o.profile},
                                {"the tool table", profile.interpreter.tool_table}};
    const NamedPath outputs[] = {{"--report", o.report}};
    auto files = open_outputs(inputs, outputs);
    if (files.empty()) return kExitUsage;
    report = std::move(files[0]);
  }
  const std::shared_ptr<tools::ToolTableService> table = electrode_tool_table(profile, o.write);
  if (!table) return kExitUsage;
  const tools::ToolEntry* entry = table->snapshot()->tool(o.tool);
  if (entry == nullptr) {
    fmt::print(stderr, "error: tool {} is not in {}\n", o.tool, profile.interpreter.tool_table);
    return kExitUsage;
  }
  Diagnostics d;
  std::optional<control::GcodeSourceConfig> config = control::GcodeProgramSource::config_for(profile, d);
  if (!config) return kExitProgram;
  config->tools = table;
  control::SimRig rig(profile, std::make_shared<control::GcodeProgramSource>(std::move(*config)));
  // The simulated electrode: where the table says, unless --sim-electrode puts it elsewhere.
  control::Point3 truth{entry->offset[0], entry->offset[1], entry->offset[2]};
  if (o.sim_electrode.size() == 3) truth = {o.sim_electrode[0], o.sim_electrode[1], o.sim_electrode[2]};
  rig.machine().set_electrode(truth, entry->diameter / 2);
  auto feature = std::make_shared<control::ElectrodeSetting>(table, profile);
  rig.controller().add_feature(feature, control::ObserverOptions{profile.servo_period_s, true});
  if (!machine_ready(rig)) return kExitProgram;
  const control::Outcome asked =
      rig.request(control::Request::feature("electrode", "measure", control::ElectrodeMeasure{o.tool}));
  if (!asked.accepted) {
    fmt::print(stderr, "error: {}\n", asked.message);
    return kExitProgram;
  }
  if (!o.json) fmt::print("{}\n", asked.message);
  const std::uint64_t started = rig.ticks();
  rig.run_until([&] { return feature->phase() == control::ElectrodePhase::Idle; }, kElectrodeMaxTicks);
  const std::optional<control::ElectrodeResult> r = feature->last();
  if (!r) {
    fmt::print(stderr, "error: the measurement did not end in {} s of machine time\n",
               static_cast<double>(kElectrodeMaxTicks) * profile.servo_period_s);
    return kExitProgram;
  }
  nlohmann::json j = result_json(*r);
  j["machine_time_s"] = static_cast<double>(rig.ticks() - started) * profile.servo_period_s;
  if (o.json) fmt::print("{}\n", j.dump(2));
  if (!o.json) print_electrode(*r);
  if (!r->ok) fmt::print(stderr, "error: {} [{}]\n", r->message, r->code);
  if (r->ok && o.write && !o.json) fmt::print("stored in {}\n", profile.interpreter.tool_table);
  if (report && !write_and_commit(*report, j.dump(2) + "\n")) return kExitUsage;
  return r->ok ? kExitOk : kExitProgram;
}

}  // namespace

void add_electrode_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<ElectrodeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "electrode-set",
      "Measure an electrode against the reference sphere (simulated machine) and store its offsets");
  cmd->add_option("--machine,-m", opts->profile, "Machine profile with [probe.reference_sphere]")->required();
  cmd->add_option("--tool,-t", opts->tool, "Tool number of the electrode in the spindle")
      ->required()
      ->check(CLI::Range(1, 99999));
  cmd->add_option("--set", opts->sets, "Override a profile key (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--sim-electrode", opts->sim_electrode,
                  "The simulated electrode's true offsets X Y Z, mm (default: the tool table's)")
      ->expected(3)
      ->delimiter(',')
      ->check(finite_range(-10000, 10000));
  cmd->add_flag("--write", opts->write, "Store the measured offsets in the profile's tool table file");
  cmd->add_flag("--json", opts->json, "Print the result as JSON");
  cmd->add_option("--report", opts->report, "Write the result as JSON to this file");
  cmd->callback([opts, &registry] { registry.set_result(electrode_set(*opts)); });
}

}  // namespace opencnc::cli
