// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc helix`: writes a helical broaching job (strokes, radial infeed, the coupling codes) for
// a constant or variable pitch, or a machine's pitch table or cam (cam::helix_program).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <map>
#include <string>

#include "cli_files.hpp"
#include "commands.hpp"
#include "numeric_options.hpp"
#include "opencnc/broaching/helix_job.hpp"

namespace opencnc::cli {

namespace {

struct HelixOptions {
  cam::HelixJob job;
  std::string output;
};

const char* type_word(cam::HelixType t) {
  switch (t) {
    case cam::HelixType::Constant:
      return "constant";
    case cam::HelixType::Variable:
      return "variable";
    case cam::HelixType::Table:
      return "table";
    case cam::HelixType::Cam:
      return "cam";
  }
  return "";
}

/// The options as they were given, for the program's header (reproducible from the file alone).
std::string command_line(const CLI::App& cmd, const HelixOptions& o) {
  std::string out = "opencnc helix";
  for (const CLI::Option* opt : cmd.get_options()) {
    if (opt->count() == 0 || opt->get_name() == "--help") continue;
    out += " " + opt->get_name();
    if (opt->get_name() == "--type") {
      out += std::string(" ") + type_word(o.job.type);
      continue;
    }
    for (const std::string& v : opt->results()) out += " " + v;
  }
  return out;
}

int run_helix(const CLI::App& cmd, const HelixOptions& o) {
  if (const auto problem = cam::validate(o.job)) {
    fmt::print(stderr, "opencnc helix: {}\n", *problem);
    return kExitUsage;
  }
  const NamedPath outputs[] = {{"-o", o.output}};
  const auto files = open_outputs({}, outputs);
  if (files.empty()) return kExitUsage;
  const std::string program = cam::helix_program(o.job, command_line(cmd, o));
  if (!write_and_commit(*files[0], program)) return kExitUsage;
  fmt::print("{}: {} groove(s) of {} strokes\n", o.output, o.job.grooves, cam::strokes_per_groove(o.job));
  return kExitOk;
}

}  // namespace

void add_helix_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<HelixOptions>();
  CLI::App* cmd = app.add_subcommand("helix", "Write a helical broaching job (M171-M175 coupling codes)");
  const std::map<std::string, cam::HelixType> types = {{"constant", cam::HelixType::Constant},
                                                       {"variable", cam::HelixType::Variable},
                                                       {"table", cam::HelixType::Table},
                                                       {"cam", cam::HelixType::Cam}};
  cam::HelixJob& j = opts->job;
  cmd->add_option("--type", j.type,
                  "constant, variable (pitch linear from --pitch to --pitch-end), table or cam")
      ->required()
      ->transform(CLI::CheckedTransformer(types, CLI::ignore_case));
  cmd->add_option("--pitch", j.pitch_mm,
                  "Pitch in mm per turn of C (at --z-start for variable; < 0: left hand)")
      ->check(finite_range(-1e6, 1e6));
  cmd->add_option("--pitch-end", j.pitch_end_mm, "Variable: the pitch at --z-end")
      ->check(finite_range(-1e6, 1e6));
  cmd->add_option("--table", j.table, "Table or cam: the machine's [[coupling.table]] number (1-8)");
  cmd->add_option("--z-start", j.z_start, "Where each cutting stroke starts, mm")
      ->check(finite_range(-1e5, 1e5));
  cmd->add_option("--z-end", j.z_end, "Where each cutting stroke ends, mm")->check(finite_range(-1e5, 1e5));
  cmd->add_option("--c-start", j.c_start, "C of the first groove at --z-start, degrees")
      ->check(finite_range(-1e6, 1e6));
  cmd->add_option("--depth", j.depth_mm, "Radial depth of the groove, mm (X)")
      ->check(finite_range(1e-6, 100));
  cmd->add_option("--infeed", j.infeed_mm, "Radial infeed per stroke, mm")->check(finite_range(1e-6, 100));
  cmd->add_option("--spring-passes", j.spring_passes, "Strokes repeated at full depth")
      ->check(CLI::Range(0, 100));
  cmd->add_option("--grooves", j.grooves, "Grooves around the bore (C indexed by 360/n)")
      ->check(CLI::Range(1, 360));
  cmd->add_option("--feed", j.feed, "Cutting feed, mm/min")->check(finite_range(1e-3, 1e6));
  cmd->add_option("--infeed-feed", j.infeed_feed, "Feed of the radial infeed, mm/min")
      ->check(finite_range(1e-3, 1e6));
  cmd->add_option("--lift", j.lift_mm, "Radial lift for the return stroke, mm")
      ->check(finite_range(1e-6, 100));
  cmd->add_flag("!--feed-return", j.rapid_return, "Return stroke at the cutting feed instead of rapid");
  cmd->add_option("-o,--output", opts->output, "The job's G-code file")->required();
  cmd->callback([cmd, opts, &registry] { registry.set_result(run_helix(*cmd, *opts)); });
}

}  // namespace opencnc::cli
