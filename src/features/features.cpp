// SPDX-License-Identifier: GPL-3.0-or-later
// The features' setups in order, and their code modules by name.
#include "opencnc/features/features.hpp"

#include "opencnc/broaching/coupling_codes.hpp"
#include "opencnc/broaching/setup.hpp"
#include "opencnc/cutting/setup.hpp"
#include "opencnc/cutting/torch_codes.hpp"
#include "opencnc/drill/setup.hpp"
#include "opencnc/edm/edm_codes.hpp"
#include "opencnc/edm/setup.hpp"
#include "opencnc/retrace/setup.hpp"
#include "opencnc/run_from_line/setup.hpp"
#include "opencnc/toolguard/tool_guard.hpp"

namespace opencnc::features {

bool set_up(controller::MachineSetup& host) {
  const config::MachineProfile& p = host.profile();
  return toolguard::setup(p, host) && drill::setup(p, host) && broaching::setup(p, host) &&
         edm::setup(p, host) && cutting::setup(p, host) && retrace::setup(p, host) &&
         run_from_line::setup(p, host);
}

std::unique_ptr<controller::MachineSetup> machine_setup(const config::MachineProfile& profile,
                                                        Diagnostics& diags,
                                                        controller::MachineSetup::Options options) {
  std::unique_ptr<controller::MachineSetup> m =
      controller::MachineSetup::create(profile, std::move(options), diags);
  if (!m) return nullptr;
  const bool ok = set_up(*m);
  for (const Diagnostic& d : m->diagnostics().items()) diags.add(d);
  return ok ? std::move(m) : nullptr;
}

std::vector<CodeModules> code_modules() {
  return {
      {"coupling", "M171-M175, the broaching codes of a machine with a [coupling] section"},
      {"plasma",
       "M190 torch on (find the plate, pierce, cut height, height control), M191 torch off, M192/M193 hold "
       "the "
       "torch height and let it go: the codes of a machine with a [process.plasma] section"},
      {"edm",
       "M180 P<n> selects machining condition n, 1-99, and switches the generator on, M181 switches it off: "
       "the codes of a machine with an [edm] section"}};
}

std::shared_ptr<const gcode::Extensions> with_code_modules(std::string_view name, gcode::Dialect dialect,
                                                           std::shared_ptr<const gcode::Extensions> base) {
  if (name == "coupling") {
    auto ext = std::make_shared<gcode::Extensions>(*base);
    gcode::add_coupling_codes(*ext);
    return ext;
  }
  if (name == "plasma") return gcode::torch_extensions(dialect, std::move(base));
  if (name == "edm") return gcode::edm_extensions(dialect, {}, std::move(base));
  return nullptr;
}

}  // namespace opencnc::features
