// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc calibrate`: homing repeatability (midpoint against a single edge) and the positioning
// test before and after compensation on the simulated machine; the measured table into the profile.
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/config/profile_writer.hpp"
#include "opencnc/controller/run_recorder.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/drill/calibration.hpp"

namespace opencnc::cli {

namespace {

struct CalibrateOptions {
  std::string profile;
  std::vector<std::string> sets;
  int homing_runs = 0;
  bool positioning = false;
  bool write_table = false;
  bool json = false;
  std::string axes;
  std::uint64_t seed = 1;
  double temperature_swing_c = 10;
  std::string trace;
};

std::string axis_key(Axis a) {
  return std::string(1, letter(a));
}

double um(double mm) {
  return std::round(mm * 1e4) / 10;  // µm to a tenth
}

/// The axes to position: the driven ones of the profile, or those `--axes` names.
std::optional<AxisMask> positioning_axes(const config::MachineProfile& p, const std::string& letters) {
  AxisMask m;
  for (const config::AxisProfile& a : p.axes) {
    if (a.manual()) continue;
    if (letters.empty() || AxisMask::from_letters(letters).has(a.axis)) m.set(a.axis);
  }
  for (char c : letters) {
    const AxisMask one = AxisMask::from_letters(std::string(1, c));
    if (one.count() != 1 || (one.bits() & m.bits()) == 0) return std::nullopt;
  }
  return m;
}

/// A file we may write an output to: not the profile we read, not a folder or a device, not a
/// read-only file.
nlohmann::json figures(const drill::AxisPositioning& a) {
  return {{"accuracy_um", um(a.accuracy)},
          {"repeatability_um", um(a.repeatability)},
          {"reversal_um", um(a.reversal)}};
}

void print_homing(const drill::HomingSpread& h) {
  fmt::print("homing: {} runs from random start positions, {:.1f} to {:.1f} °C\n", h.runs,
             h.temperature_min_c, h.temperature_max_c);
  for (int i = 0; i < kAxisCount; ++i) {
    if (!h.axes.has(static_cast<Axis>(i))) continue;
    const auto ui = static_cast<std::size_t>(i);
    fmt::print("  {}  midpoint spread {:7.2f} µm   single edge spread {:7.2f} µm\n",
               letter(static_cast<Axis>(i)), 1000 * h.midpoint_spread[ui], 1000 * h.single_edge_spread[ui]);
  }
}

void print_positioning(const drill::Positioning& before, const drill::Positioning& profile,
                       const drill::Positioning& after, const drill::PositioningOptions& o) {
  fmt::print("positioning (ISO 230-2 style): targets every {} mm, {} approaches from each direction\n",
             o.interval, o.approaches);
  for (int i = 0; i < kAxisCount; ++i) {
    if (!before.axes.has(static_cast<Axis>(i))) continue;
    const auto ui = static_cast<std::size_t>(i);
    const auto line = [&](const char* what, const drill::AxisPositioning& a) {
      fmt::print("  {}  {:<7}  accuracy {:7.1f} µm   repeatability {:7.1f} µm   reversal {:7.1f} µm\n",
                 what[0] == 'b' ? letter(static_cast<Axis>(i)) : ' ', what, um(a.accuracy),
                 um(a.repeatability), um(a.reversal));
    };
    line("before", before.axis[ui]);
    if (profile.axes.has(static_cast<Axis>(i))) line("profile", profile.axis[ui]);
    line("after", after.axis[ui]);
  }
}

/// Writes the measured tables into the profile file: never half-written (a temporary file renamed
/// over it), never when the file is no longer `original` (the text the measured profile came
/// from), and only a text that reads back as the same profile with those tables.
bool write_tables(const CalibrateOptions& o, const std::string& original,
                  const std::vector<std::pair<Axis, config::CompensationProfile>>& tables, std::string& why) {
  std::string text = original;
  for (const auto& [axis, table] : tables) {
    std::optional<std::string> next = config::with_compensation(text, axis, table, why);
    if (!next) return false;
    text = std::move(*next);
  }
  const std::filesystem::path path = std::filesystem::canonical(o.profile);
  const config::ProfileLoad check = config::parse_profile(text, path.string(), {}, path.parent_path());
  if (!check.ok()) {
    why = "the profile with the new tables does not load (nothing written)";
    return false;
  }
  for (const auto& [axis, table] : tables) {
    const config::CompensationProfile& got = check.profile->find(axis)->compensation;
    bool same = got.positions.size() == table.positions.size();
    for (std::size_t i = 0; same && i < table.positions.size(); ++i) {
      same = std::abs(got.forward[i] - table.forward[i]) < 1e-6 &&
             std::abs(got.reverse[i] - table.reverse[i]) < 1e-6 &&
             std::abs(got.positions[i] - table.positions[i]) < 1e-6;
    }
    if (!same) {
      why = fmt::format("the table of {} does not read back as measured (nothing written)", letter(axis));
      return false;
    }
  }
  return replace_profile_text(path.string(), original, text, why);
}

int calibrate(const CalibrateOptions& o) {
  if (o.homing_runs <= 0 && !o.positioning) {
    fmt::print(stderr, "error: nothing to do: give --homing-runs N and/or --positioning\n");
    return kExitUsage;
  }
  if (o.write_table && (!o.positioning || !o.sets.empty())) {
    fmt::print(stderr,
               "error: --write-table needs --positioning, and writes only what the profile as written "
               "measured (no --set)\n");
    return kExitUsage;
  }
  // With --write-table the machine is measured from the text that will be edited, read once: if
  // the file changes meanwhile, nothing is written.
  std::string original;
  if (o.write_table) {
    std::string why;
    if (!read_file(o.profile, original, &why)) {
      fmt::print(stderr, "error: {}\n", why);
      return kExitUsage;
    }
  }
  const std::filesystem::path file(o.profile);
  const config::ProfileLoad load = o.write_table
                                       ? config::parse_profile(original, o.profile, {}, file.parent_path())
                                       : config::load_profile(o.profile, o.sets);
  for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{} [{}]\n", d.format(), d.code);
  if (!load.ok()) {
    const bool unreadable =
        !load.diagnostics.items().empty() && load.diagnostics.items()[0].code == "config.file";
    return unreadable ? kExitUsage : kExitProgram;
  }
  const config::MachineProfile& profile = *load.profile;
  // The trace is checked (and created) before anything runs: never over the profile or its tools.
  std::unique_ptr<OutputFile> trace_file;
  if (!o.trace.empty()) {
    const NamedPath inputs[] = {{"the profile", o.profile}, {"the tool table", profile.interpreter.tool_table}};
    const NamedPath outputs[] = {{"--trace", o.trace}};
    auto files = open_outputs(inputs, outputs);
    if (files.empty()) return kExitUsage;
    trace_file = std::move(files[0]);
  }
  const std::optional<AxisMask> axes = positioning_axes(profile, o.axes);
  if (!axes) {
    fmt::print(stderr, "error: --axes {}: not driven axes of the profile\n", o.axes);
    return kExitUsage;
  }
  nlohmann::json out = nlohmann::json::object();
  try {
    if (o.homing_runs > 0) {
      std::optional<controller::TraceCsvWriter> csv;
      if (trace_file) csv.emplace(*trace_file, profile.axis_mask(), profile.servo_period_s);
      drill::HomingSpreadOptions ho;
      ho.runs = o.homing_runs;
      ho.seed = o.seed;
      ho.temperature_swing_c = o.temperature_swing_c;
      if (csv) ho.trace = [&](const control::TraceSample& s) { csv->add(s); };
      const drill::HomingSpread h = drill::homing_spread(profile, ho);
      if (trace_file && !commit(*trace_file)) return kExitUsage;
      if (h.axes.count() == 0)
        fmt::print(stderr, "warning: no axis homes by decel_midpoint: no homing figures\n");
      if (!o.json) print_homing(h);
      nlohmann::json& j = out["homing"] = nlohmann::json::object();
      for (int i = 0; i < kAxisCount; ++i) {
        if (!h.axes.has(static_cast<Axis>(i))) continue;
        j[axis_key(static_cast<Axis>(i))] = {
            {"midpoint_spread_um", um(h.midpoint_spread[static_cast<std::size_t>(i)])},
            {"single_edge_spread_um", um(h.single_edge_spread[static_cast<std::size_t>(i)])}};
      }
    }
    if (o.positioning) {
      drill::PositioningOptions po;
      po.axes = *axes;
      po.seed = o.seed;
      const drill::Positioning before = drill::measure_positioning(drill::without_compensation(profile), po);
      // With the profile's own tables too, where it has some: how good they are.
      drill::PositioningOptions with_own = po;
      with_own.axes = AxisMask{};
      for (const config::AxisProfile& a : profile.axes) {
        if (po.axes.has(a.axis) && a.compensation.present) with_own.axes.set(a.axis);
      }
      const drill::Positioning own =
          with_own.axes.count() > 0 ? drill::measure_positioning(profile, with_own) : drill::Positioning{};
      config::MachineProfile compensated = profile;
      std::vector<std::pair<Axis, config::CompensationProfile>> tables;
      for (config::AxisProfile& a : compensated.axes) {
        if (!before.axes.has(a.axis)) continue;
        a.compensation = drill::compensation_from(before.axis[static_cast<std::size_t>(index(a.axis))], a);
        tables.emplace_back(a.axis, a.compensation);
      }
      const drill::Positioning after = drill::measure_positioning(compensated, po);
      if (!o.json) print_positioning(before, own, after, po);
      nlohmann::json& j = out["positioning"] = nlohmann::json::object();
      for (int i = 0; i < kAxisCount; ++i) {
        if (!before.axes.has(static_cast<Axis>(i))) continue;
        const auto ui = static_cast<std::size_t>(i);
        nlohmann::json& a = j[axis_key(static_cast<Axis>(i))];
        a = {{"before", figures(before.axis[ui])}, {"after", figures(after.axis[ui])}};
        if (own.axes.has(static_cast<Axis>(i))) a["profile"] = figures(own.axis[ui]);
      }
      if (o.write_table) {
        std::string why;
        if (!write_tables(o, original, tables, why)) {
          fmt::print(stderr, "error: --write-table: {}\n", why);
          return kExitUsage;
        }
        if (!o.json) fmt::print("wrote the measured tables into {}\n", o.profile);
      }
    }
  } catch (const std::runtime_error& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitProgram;
  }
  if (o.json) fmt::print("{}\n", out.dump(2));
  return kExitOk;
}

}  // namespace

void add_calibrate_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Measure the simulated machine: homing repeatability, positioning before and after compensation");
  cmd->add_option("profile", opts->profile, "Machine profile, e.g. configs/drill-retrofit.toml")->required();
  cmd->add_option("--set", opts->sets, "Override a profile key (repeatable; not with --write-table)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--homing-runs", opts->homing_runs,
                  "Home N times from random start positions: spread of the midpoint against a single edge")
      ->check(CLI::Range(1, 10000));
  cmd->add_flag("--positioning", opts->positioning,
                "Positioning test (ISO 230-2 style) before and after compensation with the measured table");
  cmd->add_flag("--write-table", opts->write_table,
                "Write the measured tables into the profile (atomically)");
  cmd->add_option("--axes", opts->axes, "Axes to position, e.g. XY (default: every driven axis)");
  cmd->add_flag("--json", opts->json, "Print the figures as JSON");
  cmd->add_option("--seed", opts->seed, "Seed of the random start positions, temperatures and machine noise");
  cmd->add_option("--temperature-swing", opts->temperature_swing_c,
                  "Range of the homing runs' temperatures around the profile's, kelvin (default 10)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--trace", opts->trace, "Write the first homing run as a trace CSV (opencnc plot --trace)");
  cmd->callback([opts, &registry] { registry.set_result(calibrate(*opts)); });
}

}  // namespace opencnc::cli
