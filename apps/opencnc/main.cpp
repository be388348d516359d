// SPDX-License-Identifier: GPL-3.0-or-later
// opencnc command line: subcommands are registered from commands.hpp.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <new>

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
  } catch (const std::bad_alloc&) {
    // Nothing below may rely on allocating: a fixed message.
    std::fputs("\nerror: out of memory: the run needs more memory than this machine (or its limit) gives\n",
               stderr);
    return opencnc::cli::kExitFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nerror: internal error: %s (please report it with the command that caused it)\n",
                 e.what());
    return opencnc::cli::kExitFailure;
  }
  return registry.result();
}
