// SPDX-License-Identifier: GPL-3.0-or-later
// The plasma table's cut chart in a program: the library the program source reads it from (the
// store, re-read when it changes; the material selected before a program selects its own), the
// code module (M194 P<n>; G41/G42 by the kerf; M190 with the material in force) and the pass that
// warns at the line where a program's feed disagrees with the chart (docs/cutting.md).
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "opencnc/config/cut_chart_profile.hpp"
#include "opencnc/controller/extensions.hpp"
#include "opencnc/controller/machine_setup.hpp"
#include "opencnc/gcode/extension.hpp"
#include "opencnc/store/cut_chart_store.hpp"

namespace opencnc::cutting {

/// The cut chart a machine's programs read. Any thread (one lock); not real-time safe.
class CutChartLibrary {
 public:
  CutChartLibrary(std::shared_ptr<store::CutChartStore> store, const config::CutChartProfile& profile);
  /// The chart as now committed (re-read only when the store changed); null with `*error` when it
  /// cannot be read.
  std::shared_ptr<const std::vector<store::Material>> chart(std::string* error = nullptr);
  /// The material in force before a program selects one: the store's selection (the HMI's, kept
  /// in the store), else `[cut_chart] material`; 0: none.
  int selected();
  const config::CutChartProfile& profile() const noexcept { return profile_; }
  const std::shared_ptr<store::CutChartStore>& store() const noexcept { return store_; }

 private:
  std::shared_ptr<store::CutChartStore> store_;
  config::CutChartProfile profile_;
  std::mutex mutex_;
  std::shared_ptr<const std::vector<store::Material>> chart_;
  std::uint64_t seen_ = ~std::uint64_t{0};
};

/// Adds the cut chart's codes to `ext` (which has the torch's): M194 P<n> selects material n; M190,
/// G41 and G42 take the library's selected material when the program has selected none; G41/G42
/// then compensate by half the material's kerf (its D word, a tool number, is not used). What is
/// wrong (an unknown material, a G41.1/G42.1 diameter further than the tolerance from the kerf)
/// goes to the pass below as a marked comment, which puts it at its line and column.
/// Interpreter thread (the modules are shared, immutable).
void add_cut_chart_codes(gcode::Extensions& ext, std::shared_ptr<CutChartLibrary> library);

/// The pass that reports the cut chart's problems at their line and column: an unknown material
/// (an error: the preflight fails before anything moves), a compensation diameter that is not
/// the kerf, and a feed move cut with the torch on (between M190 and M191, the height not held by
/// M192) further than the tolerance from its material's feed (warnings: the run goes on; the
/// hub passes a pass's warnings to the preflight's diagnostics).
std::unique_ptr<controller::MovePass> chart_check_pass(std::shared_ptr<CutChartLibrary> library);

/// The source part with both, for MachineSetup::add_source_part.
std::shared_ptr<const controller::SourcePart> cut_chart_part(std::shared_ptr<CutChartLibrary> library);

/// With `[cut_chart]`: opens its store (an error in `host.diagnostics()` and false when it cannot)
/// and adds the part after the torch's. Nothing without. Before the controller runs.
bool setup_cut_chart(const config::MachineProfile& profile, controller::MachineSetup& host);

}  // namespace opencnc::cutting
