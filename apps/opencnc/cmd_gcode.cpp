// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc check`, `opencnc canon` and `opencnc scan`: the G-code interpreter on files.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "gcode_summary.hpp"
#include "numeric_options.hpp"
#include "opencnc/canon/rs274_printer.hpp"
#include "opencnc/core/axis_map.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/gcode/dialect.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/rs274_driver.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "progress.hpp"

namespace opencnc::cli {

namespace {

/// `check` and `scan` refuse a program still running after this much checking (an endless loop);
/// `canon` prints as rs274 does, without a bound on time.
constexpr double kDefaultCheckSeconds = 5;

struct InterpArgs {
  std::string tool_table;
  std::vector<std::string> subroutine_path;
  bool block_delete = false;
  bool no_default_tools = false;
  std::string axes = "XYZABC";
  std::string dialect;    ///< empty: the program's own marker, else LinuxCNC
  std::string machine;    ///< empty: guessed from a Fanuc program
  std::string axis_map;
  bool progress = false;  ///< progress on stderr also when it is not a terminal
  std::uint64_t max_blocks = gcode::Limits{}.max_blocks;
  /// CPU seconds a check may take (0: no bound): an endless loop is refused in seconds.
  double max_seconds = kDefaultCheckSeconds;
  std::vector<std::string> codes;  ///< code modules beyond the standard ones ("coupling", "edm")
};

void add_interp_options(CLI::App* cmd, InterpArgs& a) {
  cmd->add_option("--tool-table,-t", a.tool_table, "LinuxCNC tool table (.tbl)")->check(CLI::ExistingFile);
  cmd->add_option("--subroutine-path", a.subroutine_path,
                  "directories searched for o<name> subprogram files (default: the current directory)");
  cmd->add_flag("--block-delete,-b", a.block_delete, "skip blocks that start with '/'");
  cmd->add_option("--axes", a.axes, "axes of the machine (default XYZABC, as rs274)");
  cmd->add_flag("--no-default-tools", a.no_default_tools,
                "without --tool-table, use an empty table instead of rs274's built-in tools T1-T3");
  cmd->add_option("--dialect", a.dialect,
                  "linuxcnc or fanuc (default: the program's '(dialect: ...)' comment, else linuxcnc)")
      ->check(CLI::IsMember({"linuxcnc", "fanuc"}, CLI::ignore_case));
  cmd->add_option("--machine", a.machine, "mill or lathe, for Fanuc programs (default: guessed from the program's axis words)")
      ->check(CLI::IsMember({"mill", "lathe"}, CLI::ignore_case));
  std::string help = "code modules beyond the standard ones: ";
  std::vector<std::string> names;
  for (const features::CodeModules& m : features::code_modules()) {
    help += fmt::format("{}{} ({})", names.empty() ? "" : ", ", m.name, m.help);
    names.emplace_back(m.name);
  }
  cmd->add_option("--codes", a.codes, help)->check(CLI::IsMember(names));
  cmd->add_option("--axis-map", a.axis_map, "axis exchange, program letter = machine axis (e.g. X=Y,Y=X)");
  cmd->add_option("--max-blocks", a.max_blocks,
                  "stop with gcode.limit-blocks after this many blocks (loop bodies count each time; default "
                  "200000000)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 62));
  if (a.max_seconds > 0)
    cmd->add_option(
           "--max-seconds", a.max_seconds,
           "stop with gcode.limit-time after this many seconds of checking (an endless loop?; default 5)")
        ->check(finite_range(0.1, 1e6));
  cmd->add_flag(
      "--progress", a.progress,
      "show progress on stderr also when it is not a terminal (on a terminal it shows after 0.5 s)");
}

// rs274's built-in tool table (used when it is given no -t): tools 1..3, lengths and
// diameters in inches.
std::shared_ptr<tools::ToolTable> rs274_default_tools() {
  auto t = std::make_shared<tools::ToolTable>();
  const double z[] = {0.511, 0.1, 1.273};
  const double d[] = {0.125, 0.0625, 0.201};
  for (int i = 0; i < 3; ++i) {
    tools::ToolEntry e;
    e.tool = i + 1;
    e.pocket = i + 1;
    e.offset[Axis::Z] = z[i];
    e.diameter = d[i];
    t->add(e);
  }
  return t;
}

// Builds interpreter options for `file`; returns false (after printing why) on a bad tool
// table or axis map.
bool make_options(const InterpArgs& a, const std::string& file, gcode::Options& o) {
  o.axes = AxisMask::from_letters(a.axes);
  o.dialect = a.dialect.empty() ? gcode::dialect_marker(file).value_or(gcode::Dialect::LinuxCnc)
                                : *gcode::dialect_from_name(a.dialect);
  if (!a.machine.empty()) o.machine = *gcode::machine_kind_from_name(a.machine);
  else if (o.dialect == gcode::Dialect::Fanuc) o.machine = gcode::guess_machine_kind(file);
  if (const std::string problem = parse_axis_map(a.axis_map, o.axis_map); !problem.empty()) {
    std::fprintf(stderr, "--axis-map: %s\n", problem.c_str());
    return false;
  }
  const auto wanted = [&](std::string_view module) {
    return std::find(a.codes.begin(), a.codes.end(), module) != a.codes.end();
  };
  // The features' modules asked for, in their order (without a profile any EDM condition number
  // 1-99 is one: the machine's are checked when it opens the program).
  o.extensions = gcode::standard_extensions(o.dialect);
  for (const features::CodeModules& m : features::code_modules())
    if (wanted(m.name)) o.extensions = features::with_code_modules(m.name, o.dialect, o.extensions);
  o.block_delete = a.block_delete;
  o.limits.max_blocks = a.max_blocks;
  o.limits.max_seconds = a.max_seconds;
  o.subroutine_path = a.subroutine_path.empty() ? std::vector<std::string>{"."} : a.subroutine_path;
  if (!a.tool_table.empty()) {
    Diagnostics diags;
    auto table = tools::ToolTable::load(a.tool_table, diags);
    for (const auto& d : diags.items()) std::fprintf(stderr, "%s [%s]\n", d.format().c_str(), d.code.c_str());
    if (!table || diags.has_errors()) return false;
    o.tool_table = std::make_shared<tools::ToolTable>(std::move(*table));
  } else if (!a.no_default_tools) {
    o.tool_table = rs274_default_tools();
  }
  return true;
}

void print_diagnostics(const Diagnostics& diags) {
  for (const auto& d : diags.items()) std::fprintf(stderr, "%s [%s]\n", d.format().c_str(), d.code.c_str());
}

int run_canon(const std::string& file, const InterpArgs& args) {
  gcode::Options options;
  if (!make_options(args, file, options)) return kExitUsage;
  gcode::Interpreter interp(options);
  if (!interp.open(file)) {
    print_diagnostics(interp.diagnostics());
    return kExitUsage;
  }
  canon::Rs274Printer printer(stdout, stdout);
  InterpreterProgress progress("canon " + file, args.progress);
  const gcode::RunStatus status = gcode::run_like_rs274(
      interp, printer, [&](gcode::Interpreter& i, canon::Sink& sink) { return progress.run(i, sink); });
  printer.flush();
  print_diagnostics(interp.diagnostics());
  return status == gcode::RunStatus::Error ? kExitProgram : kExitOk;
}

// Runs every file without output; reports each problem as file:line:col.
int run_check(const std::vector<std::string>& files, const InterpArgs& args) {
  bool errors = false;
  bool unreadable = false;
  for (const std::string& file : files) {
    gcode::Options options;
    if (!make_options(args, file, options)) return kExitUsage;
    gcode::Interpreter interp(options);
    canon::Sink quiet;
    if (!interp.open(file)) {
      unreadable = true;
    } else {
      InterpreterProgress("check " + file, args.progress).run(interp, quiet);
    }
    for (const auto& d : interp.diagnostics().items()) std::printf("%s [%s]\n", d.format().c_str(), d.code.c_str());
    errors = errors || interp.diagnostics().has_errors();
  }
  if (unreadable) return kExitUsage;
  return errors ? kExitProgram : kExitOk;
}

}  // namespace

void add_gcode_commands(CLI::App& app, Registry& registry) {
  static InterpArgs check_args, canon_args, scan_args;
  canon_args.max_seconds = 0;  // rs274's output, however long the program
  static std::vector<std::string> check_files;
  static std::string canon_file, scan_file;
  static ScanOutput scan_out;

  CLI::App* check = app.add_subcommand("check", "Check G-code programs without moving anything");
  check->add_option("files", check_files, "programs to check")->required();
  add_interp_options(check, check_args);
  check->callback([&registry] { registry.set_result(run_check(check_files, check_args)); });

  CLI::App* canon_cmd = app.add_subcommand("canon", "Print the canonical machining calls of a program (rs274 -g format)");
  canon_cmd->add_option("file", canon_file, "program")->required();
  add_interp_options(canon_cmd, canon_args);
  canon_cmd->callback([&registry] { registry.set_result(run_canon(canon_file, canon_args)); });

  CLI::App* scan = app.add_subcommand("scan", "Summarise a program: moves, length, extents, time, tools, offsets");
  scan->add_option("file", scan_file, "program")->required();
  scan->add_flag("--json", scan_out.json, "print the summary as JSON");
  scan->add_option("--rapid-rate", scan_out.rapid_rate_mm_min,
                   "rapid rate in mm/min for the time estimate (default: rapids not timed)")
      ->check(finite_range(0.0, 1e9));
  add_interp_options(scan, scan_args);
  scan->callback([&registry] {
    gcode::Options options;
    if (!make_options(scan_args, scan_file, options)) {
      registry.set_result(kExitUsage);
      return;
    }
    scan_out.progress = scan_args.progress;
    registry.set_result(run_scan(scan_file, options, scan_out));
  });
}

}  // namespace opencnc::cli
