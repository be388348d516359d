// SPDX-License-Identifier: GPL-3.0-or-later
// The list of subcommands, one file each (cmd_*.cpp).
#include "commands.hpp"

#include <CLI/CLI.hpp>

namespace opencnc::cli {

void register_all(CLI::App& app, Registry& registry) {
  add_latency_command(app, registry);
  add_profile_command(app, registry);
  add_gcode_commands(app, registry);
  add_run_command(app, registry);
  add_plot_command(app, registry);
  add_calibrate_command(app, registry);
  add_electrode_command(app, registry);
  add_calibrate_b_command(app, registry);
  add_tools_command(app, registry);
  add_cutchart_command(app, registry);
  add_nearest_command(app, registry);
  add_serve_command(app, registry);
  add_fleet_command(app, registry);
  add_helix_command(app, registry);
  add_recover_command(app, registry);
  add_edm_command(app, registry);
}

}  // namespace opencnc::cli
