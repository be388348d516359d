// SPDX-License-Identifier: GPL-3.0-or-later
// Run from line on a machine: the feature with a program source of its own, added to the hub.
#include "opencnc/run_from_line/setup.hpp"

#include "opencnc/run_from_line/run_from_line.hpp"

namespace opencnc::run_from_line {

// The scan runs with a source of its own (the controller's is the controller's), reading the
// controller's tool table (a scan's G10 L1 writes only a copy of its own).
bool setup(const config::MachineProfile& profile, controller::MachineSetup& host) {
  std::shared_ptr<tools::ToolTableService> live = host.source_config().tools;
  auto tools = live ? std::make_shared<run_from_line::ScanToolTable>(std::move(live)) : nullptr;
  auto feature = std::make_shared<run_from_line::RunFromLineFeature>(host.make_source(tools), tools);
  host.add_feature(feature, controller::ObserverOptions{profile.servo_period_s, false});
  return true;
}

}  // namespace opencnc::run_from_line
