// SPDX-License-Identifier: GPL-3.0-or-later
// Subcommand registration for the opencnc command line.
#pragma once

#include <functional>

namespace CLI {
class App;
}

namespace opencnc::cli {

inline constexpr int kExitOk = 0;       ///< success
inline constexpr int kExitProgram = 1;  ///< the program (G-code, machine) has an error
inline constexpr int kExitUsage = 2;    ///< wrong command line, unreadable input, unwritable output
inline constexpr int kExitFailure = 3;  ///< opencnc itself failed (out of memory, an internal error)

/// Holds the exit code of the subcommand that ran.
class Registry {
 public:
  void set_result(int rc) { result_ = rc; }
  int result() const { return result_; }

 private:
  int result_ = kExitOk;
};

/// Adds every subcommand to `app`; each callback stores its exit code in `registry`.
void register_all(CLI::App& app, Registry& registry);

// One function per subcommand (cmd_<name>.cpp).
void add_latency_command(CLI::App& app, Registry& registry);
void add_profile_command(CLI::App& app, Registry& registry);
// One function per subcommand group (cmd_<name>.cpp).
void add_gcode_commands(CLI::App& app, Registry& registry);   ///< check, canon, scan
void add_run_command(CLI::App& app, Registry& registry);
void add_plot_command(CLI::App& app, Registry& registry);
void add_calibrate_command(CLI::App& app, Registry& registry);
void add_tools_command(CLI::App& app, Registry& registry);  ///< the tool store and its guard
void add_cutchart_command(CLI::App& app, Registry& registry);  ///< the plasma table's cut chart
void add_nearest_command(CLI::App& app, Registry& registry);
void add_edm_command(CLI::App& app, Registry& registry);     ///< edm sequence
void add_serve_command(CLI::App& app, Registry& registry);   ///< the HMI server
void add_fleet_command(CLI::App& app, Registry& registry);   ///< the fleet view
void add_helix_command(CLI::App& app, Registry& registry);
void add_electrode_command(CLI::App& app, Registry& registry);  ///< electrode-set
void add_calibrate_b_command(CLI::App& app, Registry& registry);  ///< calibrate-b
void add_recover_command(CLI::App& app, Registry& registry);  ///< power-fail recovery

}  // namespace opencnc::cli
