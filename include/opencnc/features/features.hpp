// SPDX-License-Identifier: GPL-3.0-or-later
// The machine features the command line and the HMI know, set up in one place: the only code that
// names them all (docs/code-overview.md, "How to add a machine feature").
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "opencnc/controller/machine_setup.hpp"
#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::features {

/// Every feature's setup(profile, host) on `host`, in this order: the tool guard (it gives the
/// program source its tool table), the drill's hand-fed axes, broaching, the EDM, retrace, run
/// from line — those that add passes and modules before those that make program sources of their
/// own. Each adds what the profile calls for. False at the first that fails (its reasons in
/// host.diagnostics()). Before the controller runs, on the thread that sets it up.
bool set_up(controller::MachineSetup& host);

/// A machine with every feature `profile` calls for (controller::MachineSetup::create, then set_up),
/// for the tools and tests that take the whole set; null with the reasons in `diags`.
std::unique_ptr<controller::MachineSetup> machine_setup(const config::MachineProfile& profile,
                                                        Diagnostics& diags,
                                                        controller::MachineSetup::Options options = {});

/// A feature's code modules a program may be checked with without a machine (`opencnc check
/// --codes NAME`).
struct CodeModules {
  std::string_view name;  ///< "coupling", "edm"
  std::string_view help;  ///< what they are, for the option's help
};
/// The features' code modules, in the order they are added: coupling, edm.
std::vector<CodeModules> code_modules();

/// `base` with the code modules named `name` added (any condition number for the EDM's: a
/// machine's are checked when it opens the program); null for a name no feature has. Any thread.
std::shared_ptr<const gcode::Extensions> with_code_modules(std::string_view name, gcode::Dialect dialect,
                                                           std::shared_ptr<const gcode::Extensions> base);

}  // namespace opencnc::features
