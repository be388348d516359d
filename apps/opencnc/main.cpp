// SPDX-License-Identifier: GPL-3.0-or-later
// opencnc command line: subcommands are registered from commands.hpp.
#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"opencnc — PC-based CNC controller"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "opencnc 0.1.0");
  opencnc::cli::Registry registry;
  opencnc::cli::register_all(app, registry);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 returns 0 for --help/--version and its own codes for usage errors; usage is 2.
    int rc = app.exit(e);
    return rc == 0 ? 0 : opencnc::cli::kExitUsage;
  }
  return registry.result();
}
