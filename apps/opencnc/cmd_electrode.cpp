// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc electrode-set`: measure an electrode against the reference sphere on the simulated
// machine and store its offsets in the tool table; `opencnc calibrate-b`: B's axis of rotation
// from the sphere at several B angles, written into the profile (docs/electrode-setting.md).
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <any>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/config/toml_edit.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/edm/electrode_setting.hpp"
#include "opencnc/features/features.hpp"

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

nlohmann::json json_point(const Vec3& p) {
  return {p[0], p[1], p[2]};
}

nlohmann::json result_json(const edm::ElectrodeResult& r) {
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

void print_electrode(const edm::ElectrodeResult& r) {
  for (std::size_t i = 0; i < r.touched.size(); ++i)
    fmt::print("  touch {:<5} X{:.4f} Y{:.4f} Z{:.4f}\n", i < r.names.size() ? r.names[i] : "",
               r.touched[i][0], r.touched[i][1], r.touched[i][2]);
  if (!r.ok) return;
  fmt::print("tool {}: X {:.4f}  Y {:.4f}  Z (length) {:.4f} mm; before X {:.4f}  Y {:.4f}  Z {:.4f}\n",
             r.tool, r.offset[0], r.offset[1], r.offset[2], r.previous[0], r.previous[1], r.previous[2]);
  fmt::print("fit: residual {:.1f} µm rms, {:.1f} µm at most\n", 1000 * r.rms_residual_mm,
             1000 * r.max_residual_mm);
}

bool machine_ready(controller::SimRig& rig) {
  using control::CommandKind;
  using controller::Request;
  const auto must = [&](Request r) {
    const controller::Outcome o = rig.request(std::move(r), 100000);
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

/// The simulated machine with the electrode feature, homed, tool `tool`'s electrode in the spindle
/// (where the table says, or `sim_electrode`), and the report file opened.
struct SphereSession {
  std::unique_ptr<controller::SimRig> rig;
  std::shared_ptr<edm::ElectrodeSetting> feature;
  std::unique_ptr<OutputFile> report;
};

/// Opens the session for `profile` (read from `path`); an exit code when it cannot.
std::optional<int> open_session(const config::MachineProfile& profile, const std::string& path, int tool,
                                const std::vector<double>& sim_electrode, bool write_table,
                                const std::string& report_path, SphereSession& s) {
  const config::ReferenceSphereProfile& sphere = profile.probe.reference_sphere;
  if (!sphere.present || !sphere.sim) {
    fmt::print(stderr, "error: {} has no {}: nothing to touch\n", path,
               sphere.present ? "[probe.reference_sphere.sim] (the simulated machine's sphere)"
                              : "[probe.reference_sphere]");
    return kExitUsage;
  }
  if (profile.interpreter.tool_table.empty()) {
    fmt::print(stderr, "error: {} names no tool table ([interpreter] tool_table)\n", path);
    return kExitUsage;
  }
  if (!report_path.empty()) {
    const NamedPath inputs[] = {{"the profile", path}, {"the tool table", profile.interpreter.tool_table}};
    const NamedPath outputs[] = {{"--report", report_path}};
    auto files = open_outputs(inputs, outputs);
    if (files.empty()) return kExitUsage;
    s.report = std::move(files[0]);
  }
  // The machine as every front end sets it up; its tool table the file itself with --write (every
  // change written back), else a copy in memory.
  Diagnostics d;
  controller::MachineSetup::Options asked;
  if (!write_table) asked.settings["tool-table"] = "memory";
  std::unique_ptr<controller::MachineSetup> machine = features::machine_setup(profile, d, std::move(asked));
  for (const Diagnostic& i : d.items()) fmt::print(stderr, "{} [{}]\n", i.format(), i.code);
  if (!machine) return kExitUsage;
  s.feature = std::dynamic_pointer_cast<edm::ElectrodeSetting>(machine->feature("electrode"));
  if (!s.feature) {
    fmt::print(stderr, "error: {} has no reference sphere and tool table to set electrodes with\n", path);
    return kExitUsage;
  }
  const std::shared_ptr<tools::ToolTableService> table = machine->source_config().tools;
  const tools::ToolEntry* entry = table->snapshot()->tool(tool);
  if (entry == nullptr) {
    fmt::print(stderr, "error: tool {} is not in {}\n", tool, profile.interpreter.tool_table);
    return kExitUsage;
  }
  s.rig = std::make_unique<controller::SimRig>(profile, *machine);
  // The simulated electrode: where the table says, unless --sim-electrode puts it elsewhere.
  Vec3 truth{entry->offset[0], entry->offset[1], entry->offset[2]};
  if (sim_electrode.size() == 3) truth = {sim_electrode[0], sim_electrode[1], sim_electrode[2]};
  s.rig->machine().set_electrode(truth, entry->diameter / 2);
  if (!machine_ready(*s.rig)) return kExitProgram;
  return std::nullopt;
}

/// Asks the feature and runs the machine until it is idle again; false (said on stderr) if refused.
bool run_feature(SphereSession& s, const std::string& action, std::any args, bool quiet) {
  const controller::Outcome asked =
      s.rig->request(controller::Request::feature("electrode", action, std::move(args)));
  if (!asked.accepted) {
    fmt::print(stderr, "error: {}\n", asked.message);
    return false;
  }
  if (!quiet) fmt::print("{}\n", asked.message);
  s.rig->run_until([&] { return s.feature->phase() == edm::ElectrodePhase::Idle; }, kElectrodeMaxTicks);
  return true;
}

int electrode_set(const ElectrodeOptions& o) {
  const config::ProfileLoad load = config::load_profile(o.profile, o.sets);
  for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{} [{}]\n", d.format(), d.code);
  if (!load.ok()) return load.diagnostics.items()[0].code == "config.file" ? kExitUsage : kExitProgram;
  const config::MachineProfile& profile = *load.profile;
  SphereSession s;
  if (const std::optional<int> failed =
          open_session(profile, o.profile, o.tool, o.sim_electrode, o.write, o.report, s))
    return *failed;
  controller::SimRig& rig = *s.rig;
  const std::uint64_t started = rig.ticks();
  if (!run_feature(s, "measure", edm::ElectrodeMeasure{o.tool}, o.json)) return kExitProgram;
  const std::optional<edm::ElectrodeResult> r = s.feature->last();
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
  if (s.report && !write_and_commit(*s.report, j.dump(2) + "\n")) return kExitUsage;
  return r->ok ? kExitOk : kExitProgram;
}

// --- calibrate-b -------------------------------------------------------------------------------

struct BAxisOptions {
  std::string profile;
  std::vector<std::string> sets;
  int tool = 0;
  std::vector<double> angles;
  std::vector<double> sim_electrode;
  bool write = false;
  bool json = false;
  std::string report;
};

nlohmann::json b_axis_json(const edm::BAxisResult& r) {
  nlohmann::json centres = nlohmann::json::array();
  for (std::size_t k = 0; k < r.centres.size(); ++k)
    centres.push_back({{"b_deg", r.angles_deg[k]}, {"centre", json_point(r.centres[k])}});
  nlohmann::json j = {
      {"ok", r.ok},
      {"code", r.code},
      {"message", r.message},
      {"tool", r.tool},
      {"angles_deg", r.angles_deg},
      {"centres", centres},
      {"previous", {{"b_axis", r.previous.crossing}, {"b_axis_direction", r.previous.direction}}}};
  if (r.fit.radius_mm > 0) {
    j["b_axis"] = r.fit.axis.crossing;
    j["b_axis_direction"] = r.fit.axis.direction;
    j["radius_mm"] = r.fit.radius_mm;
    j["rms_residual_um"] = electrode_um(r.fit.rms_residual_mm);
    j["max_residual_um"] = electrode_um(r.fit.max_residual_mm);
    j["moved_um"] = {electrode_um(r.fit.axis.crossing[0] - r.previous.crossing[0]),
                     electrode_um(r.fit.axis.crossing[1] - r.previous.crossing[1])};
  }
  return j;
}

std::string toml_list(std::span<const double> v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i > 0 ? ", " : "") + config::toml_number(v[i]);
  return s + "]";
}

/// The profile's text with the measured axis in [probe.reference_sphere], written over the file
/// (replace_profile_text) once it reads back as the same profile with that axis.
bool write_b_axis(const std::string& path, const std::string& original, const edm::BAxisLine& axis,
                  std::string& why) {
  std::optional<std::string> text =
      config::with_toml_value(original, "probe.reference_sphere.b_axis", toml_list(axis.crossing), why);
  if (text)
    text = config::with_toml_value(*text, "probe.reference_sphere.b_axis_direction",
                                   toml_list(axis.direction), why);
  if (!text) return false;
  const std::filesystem::path file = std::filesystem::canonical(path);
  const config::ProfileLoad check = config::parse_profile(*text, file.string(), {}, file.parent_path());
  const config::ReferenceSphereProfile* got = check.ok() ? &check.profile->probe.reference_sphere : nullptr;
  if (got == nullptr || !got->has_b_axis || got->b_axis != axis.crossing) {
    why = "the profile with the measured axis does not read back as measured (nothing written)";
    return false;
  }
  return replace_profile_text(file.string(), original, *text, why);
}

int calibrate_b(const BAxisOptions& o) {
  if (o.write && !o.sets.empty()) {
    fmt::print(stderr,
               "error: --write writes only what the profile as written was measured with: no --set\n");
    return kExitUsage;
  }
  std::string original, why;
  if (!read_file(o.profile, original, &why)) {
    fmt::print(stderr, "error: {}\n", why);
    return kExitUsage;
  }
  // Measured from the very text --write edits (read once).
  const std::filesystem::path file = std::filesystem::absolute(o.profile);
  const config::ProfileLoad load = config::parse_profile(original, o.profile, o.sets, file.parent_path());
  for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{} [{}]\n", d.format(), d.code);
  if (!load.ok()) return kExitProgram;
  const config::MachineProfile& profile = *load.profile;
  const config::AxisProfile* b = profile.find(Axis::B);
  if (b == nullptr) {
    fmt::print(stderr, "error: {} has no B axis\n", o.profile);
    return kExitUsage;
  }
  std::vector<double> angles = o.angles;
  const double at = profile.probe.reference_sphere.b_deg;
  if (angles.empty()) angles = {at - 45, at, at + 45};
  SphereSession s;
  if (const std::optional<int> failed =
          open_session(profile, o.profile, o.tool, o.sim_electrode, false, o.report, s))
    return *failed;
  const std::uint64_t started = s.rig->ticks();
  if (!run_feature(s, "calibrate-b", edm::BAxisCalibrate{o.tool, angles}, o.json)) return kExitProgram;
  const std::optional<edm::BAxisResult> r = s.feature->last_b_axis();
  if (!r) {
    fmt::print(stderr, "error: the calibration did not end in {} s of machine time\n",
               static_cast<double>(kElectrodeMaxTicks) * profile.servo_period_s);
    return kExitProgram;
  }
  nlohmann::json j = b_axis_json(*r);
  j["machine_time_s"] = static_cast<double>(s.rig->ticks() - started) * profile.servo_period_s;
  if (o.json) fmt::print("{}\n", j.dump(2));
  if (!o.json) {
    for (std::size_t k = 0; k < r->centres.size(); ++k)
      fmt::print("  B {:>8.3f}°  centre X{:.4f} Y{:.4f} Z{:.4f}\n", r->angles_deg[k], r->centres[k][0],
                 r->centres[k][1], r->centres[k][2]);
    fmt::print("{}\n", r->message);
  }
  if (!r->ok) fmt::print(stderr, "error: {} [{}]\n", r->message, r->code);
  if (r->ok && o.write) {
    if (!write_b_axis(o.profile, original, r->fit.axis, why)) {
      fmt::print(stderr, "error: --write: {}\n", why);
      return kExitProgram;
    }
    if (!o.json) fmt::print("stored in {} (probe.reference_sphere.b_axis, b_axis_direction)\n", o.profile);
  }
  if (s.report && !write_and_commit(*s.report, j.dump(2) + "\n")) return kExitUsage;
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

void add_calibrate_b_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<BAxisOptions>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate-b",
      "Measure B's axis of rotation from the reference sphere at several B angles (simulated machine)");
  cmd->add_option("--machine,-m", opts->profile,
                  "Machine profile with B and [probe.reference_sphere] with its nominal b_axis")
      ->required();
  cmd->add_option("--tool,-t", opts->tool, "Tool number of the electrode in the spindle")
      ->required()
      ->check(CLI::Range(1, 99999));
  cmd->add_option("--angles", opts->angles,
                  "B angles to measure the sphere at, degrees, at least three (default: b-45,b,b+45)")
      ->delimiter(',')
      ->check(finite_range(-100000, 100000));
  cmd->add_option("--set", opts->sets, "Override a profile key (repeatable; not with --write)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--sim-electrode", opts->sim_electrode,
                  "The simulated electrode's true offsets X Y Z, mm (default: the tool table's)")
      ->expected(3)
      ->delimiter(',')
      ->check(finite_range(-10000, 10000));
  cmd->add_flag("--write", opts->write,
                "Write the measured axis into the profile (probe.reference_sphere.b_axis, atomically)");
  cmd->add_flag("--json", opts->json, "Print the result as JSON");
  cmd->add_option("--report", opts->report, "Write the result as JSON to this file");
  cmd->callback([opts, &registry] { registry.set_result(calibrate_b(*opts)); });
}

}  // namespace opencnc::cli
