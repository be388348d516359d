// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc edm sequence`: the roughing-to-finishing condition sequence for an electrode's frontal
// area, the finish and the undersize from the profile's technology table, printed and, with
// --program, written as a program of M180 P<n> Q<orbit> steps (docs/edm.md).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/edm/sequence.hpp"

namespace opencnc::cli {

namespace {

struct EdmSequenceOptions {
  std::string machine;
  std::vector<std::string> sets;
  double area_mm2 = 0;
  std::string finish;
  double undersize_mm = 0;
  std::string program;
  double surface = 0;
  double depth_mm = 0;
};

int run_edm_sequence(const EdmSequenceOptions& o) {
  const NamedPath inputs[] = {{"--machine", o.machine}};
  if (!check_inputs(inputs)) return kExitUsage;
  if (!o.program.empty() && !(o.depth_mm > 0)) {
    fmt::print(stderr, "error: --program needs --depth (how deep below --surface the burn goes, mm)\n");
    return kExitUsage;
  }
  const std::variant<double, std::string> finish = edm::parse_finish(o.finish);
  if (const auto* why = std::get_if<std::string>(&finish)) {
    fmt::print(stderr, "error: {}\n", *why);
    return kExitUsage;
  }
  const config::ProfileLoad load = config::load_profile(o.machine, o.sets);
  for (const Diagnostic& x : load.diagnostics.items()) fmt::print(stderr, "{}\n", x.format());
  if (!load.ok()) return kExitUsage;
  const config::MachineProfile& p = *load.profile;
  if (!p.edm.present) {
    fmt::print(stderr, "error: {} is not a sinker EDM (no [edm] section)\n", o.machine);
    return kExitUsage;
  }
  const edm::SequenceRequest request{o.area_mm2, std::get<double>(finish), o.undersize_mm};
  const std::variant<edm::Sequence, std::string> planned = edm::plan_sequence(p.edm.config, request);
  if (const auto* why = std::get_if<std::string>(&planned)) {
    fmt::print(stderr, "error: {}\n", *why);
    return kExitProgram;
  }
  const edm::Sequence& s = std::get<edm::Sequence>(planned);
  fmt::print("{}", edm::sequence_text(s));
  if (o.program.empty()) return kExitOk;
  // Checked before anything is written: never over the profile nor any other input.
  const NamedPath outputs[] = {{"--program", o.program}};
  std::vector<std::unique_ptr<OutputFile>> out = open_outputs(inputs, outputs);
  if (out.empty() || !out[0]) return kExitUsage;
  const char letter = static_cast<char>("XYZABCUVW"[p.edm.config.tool_axis]);
  const std::string text =
      edm::sequence_program(s, p.edm.config, letter, o.surface, o.depth_mm, p.edm.config.lift_direction);
  if (!write_and_commit(*out[0], text)) return kExitUsage;
  fmt::print("written to {}\n", o.program);
  return kExitOk;
}

}  // namespace

void add_edm_command(CLI::App& app, Registry& registry) {
  CLI::App* edm = app.add_subcommand("edm", "Sinker EDM: condition sequences from the technology table");
  edm->require_subcommand(1);
  auto o = std::make_shared<EdmSequenceOptions>();
  CLI::App* cmd = edm->add_subcommand(
      "sequence",
      "The roughing-to-finishing condition sequence for an electrode's frontal area, a finish and an "
      "undersize (the profile's conditions with ra_um and side_gap_mm)");
  cmd->add_option("--machine,-m", o->machine, "machine profile with [edm] conditions")->required();
  cmd->add_option("--set", o->sets, "override a profile key (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--area", o->area_mm2, "the electrode's frontal area, mm²")
      ->required()
      ->check(finite_range(1e-6, 1e7));
  cmd->add_option("--finish", o->finish, "the finish: Ra in µm (0.8, Ra0.8) or a VDI 3400 class (VDI18)")
      ->required();
  cmd->add_option("--undersize", o->undersize_mm, "the electrode's undersize per side, mm")
      ->required()
      ->check(finite_range(1e-6, 10));
  cmd->add_option("--program,-o", o->program, "write the sequence as a program here (never over an input)");
  cmd->add_option("--surface", o->surface,
                  "the work's surface along the tool axis, where the tip touches (mm)")
      ->check(finite_range(-1e6, 1e6));
  cmd->add_option("--depth", o->depth_mm, "how deep below the surface the electrode's tip goes (mm)")
      ->check(finite_range(1e-6, 1e4));
  cmd->callback([o, &registry] { registry.set_result(run_edm_sequence(*o)); });
}

}  // namespace opencnc::cli
