// SPDX-License-Identifier: GPL-3.0-or-later
// `[cut_chart]` of a plasma table's profile: where its cut chart is, the material in force before a
// program selects one, the check's tolerances (docs/cutting.md, "Cut charts").
#pragma once

#include <optional>
#include <string>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/core/diagnostic.hpp"

namespace opencnc::config {

struct CutChartProfile {
  std::string store;                ///< the SQLite cut chart (relative to the profile)
  int material = 0;                 ///< in force before `M194 P<n>` (0: none; the HMI selects one)
  double feed_tolerance = 0.1;      ///< a feed further than this share from the chart's warns
  double kerf_tolerance_mm = 0.05;  ///< a G41.1/G42.1 diameter further than this from the kerf warns
};

/// The `[cut_chart]` of the file `profile` was read from, with its `--set` overrides (the loader
/// checked it already; a profile made in memory has none): nothing when there is none, or when
/// it cannot be read again (then an error in `diags`). Non-real-time; any thread.
std::optional<CutChartProfile> cut_chart_profile(const MachineProfile& profile, Diagnostics& diags);

}  // namespace opencnc::config
