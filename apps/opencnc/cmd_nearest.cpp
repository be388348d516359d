// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc nearest`: the nearest point of a program's feed path to a point (flame retrace's C),
// from the path index of the program as the machine would run it (docs/retrace.md).
#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "opencnc/retrace/path_scan.hpp"

namespace opencnc::cli {

namespace {

struct NearestOptions {
  std::string file;
  std::vector<double> point;
  bool three_d = false;
  std::string machine;
  std::vector<std::string> sets;
  double margin_mm = 0.5;
  bool json = false;
};

/// The profile's G-code source, or a plain one (millimetres, X Y Z A B C, no tool table).
std::shared_ptr<controller::GcodeProgramSource> make_source(const NearestOptions& o, int& rc) {
  Diagnostics d;
  if (o.machine.empty()) {
    controller::GcodeSourceConfig c;
    c.options.user_units = canon::Units::Mm;
    c.options.initial_units = canon::Units::Mm;
    return std::make_shared<controller::GcodeProgramSource>(std::move(c));
  }
  const config::ProfileLoad load = config::load_profile(o.machine, o.sets);
  for (const Diagnostic& x : load.diagnostics.items()) fmt::print(stderr, "{}\n", x.format());
  if (!load.ok()) {
    const bool unreadable =
        !load.diagnostics.items().empty() && load.diagnostics.items()[0].code == "config.file";
    rc = unreadable ? kExitUsage : kExitProgram;
    return nullptr;
  }
  // The program as the machine runs it: its features' passes and codes (features::machine_setup).
  std::unique_ptr<controller::MachineSetup> machine = features::machine_setup(*load.profile, d);
  for (const Diagnostic& x : d.items()) fmt::print(stderr, "{}\n", x.format());
  if (!machine) {
    rc = kExitProgram;
    return nullptr;
  }
  return machine->source();
}

nlohmann::json point_json(const recovery::PathPoint& p, const recovery::PathIndex& ix) {
  nlohmann::json j;
  j["distance"] = p.distance_mm;
  j["point"] = {p.point[0], p.point[1], p.point[2]};
  j["segment"] = p.segment;
  const controller::SourceLocation l = controller::locate(*ix.sources(), p.context, p.line);
  j["line"] = fmt::format("{}:{}", l.file, l.line);
  j["calls"] = l.calls;
  j["param"] = p.param;
  return j;
}

int run_nearest(const NearestOptions& o) {
  const NamedPath inputs[] = {{"program", o.file}, {"--machine", o.machine}};
  if (!check_inputs(inputs)) return kExitUsage;
  int rc = kExitOk;
  const auto source = make_source(o, rc);
  if (!source) return rc;
  const auto t0 = std::chrono::steady_clock::now();
  Diagnostics d;
  const recovery::PathIndex ix = recovery::scan_path(*source, o.file, Pose{}, {}, d);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const Diagnostic& x : d.items()) fmt::print(stderr, "{}\n", x.format());
  if (d.has_errors()) return kExitProgram;
  recovery::QueryOptions q;
  q.metric = o.three_d ? recovery::Metric::Xyz : recovery::Metric::Xy;
  q.margin_mm = o.margin_mm;
  const Vec3 b{o.point[0], o.point[1], o.point.size() > 2 ? o.point[2] : 0.0};
  const recovery::Nearest n = ix.nearest(b, q);
  if (!n.found) {
    fmt::print(stderr, "error: {} has no feed moves\n", o.file);
    return kExitProgram;
  }
  if (o.json) {
    nlohmann::json j = point_json(n.nearest, ix);
    nlohmann::json c = nlohmann::json::array();
    for (const recovery::PathPoint& p : n.candidates) c.push_back(point_json(p, ix));
    j["candidates"] = c;
    j["feed_moves"] = ix.size();
    j["index_s"] = build_s;
    fmt::print("{}\n", j.dump(2));
    return kExitOk;
  }
  for (std::size_t i = 0; i < n.candidates.size(); ++i) {
    const recovery::PathPoint& p = n.candidates[i];
    fmt::print("{} ({:.4f}, {:.4f}, {:.4f})  {:.4f} mm away  segment {}  {}\n",
               i == 0 ? "nearest  " : "candidate", p.point[0], p.point[1], p.point[2], p.distance_mm,
               p.segment, controller::to_string(controller::locate(*ix.sources(), p.context, p.line)));
  }
  fmt::print("{} feed moves indexed in {:.3f} s\n", ix.size(), build_s);
  return kExitOk;
}

}  // namespace

void add_nearest_command(CLI::App& app, Registry& registry) {
  auto o = std::make_shared<NearestOptions>();
  CLI::App* cmd = app.add_subcommand("nearest",
                                     "The nearest point of a program's feed path to X Y [Z] (flame/plasma "
                                     "retrace), kerf compensation applied");
  cmd->add_option("file", o->file, "G-code program")->required();
  cmd->add_option("point", o->point, "X Y [Z], machine coordinates, mm")
      ->required()
      ->expected(2, 3)
      ->check(finite_range(-1e9, 1e9));
  cmd->add_flag("--3d", o->three_d, "measure in space (default: in the XY plane, the torch height ignored)");
  cmd->add_option("--machine,-m", o->machine, "machine profile (dialect, tool table for the kerf, axes)");
  cmd->add_option("--set", o->sets, "override a profile key (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--margin", o->margin_mm,
                  "other stretches of the path within this much of the nearest distance are candidates (mm, "
                  "default 0.5)")
      ->check(finite_range(0, 1e6));
  cmd->add_flag("--json", o->json, "print the answer as JSON (distance, point, segment, line, candidates)");
  cmd->callback([o, &registry] { registry.set_result(run_nearest(*o)); });
}

}  // namespace opencnc::cli
