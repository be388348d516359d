// SPDX-License-Identifier: GPL-3.0-or-later
// The sinker EDM's codes: M180 P<n> selects machining condition n and switches the generator on
// (feed moves then run under the gap servo), M181 switches it off (docs/edm.md).
#pragma once

#include <memory>
#include <vector>

#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/options.hpp"

namespace opencnc::gcode {

/// Registers M180 and M181 in `ext`; M180's P must be one of `conditions` (the machine's
/// condition numbers; empty: any of 1–99), its optional Q (the burn's orbit radius) at most the
/// condition's `orbits` entry (its orbit_radius_mm, 0: no orbit; empty: not checked). Non-real-time.
void add_edm_codes(Extensions& ext, std::vector<int> conditions, std::vector<double> orbits = {});

/// `base` (or standard_extensions(dialect)) with the EDM codes: what a machine with an [edm]
/// section gives GcodeSourceConfig::extensions. Non-real-time; any thread.
std::shared_ptr<const Extensions> edm_extensions(Dialect dialect, std::vector<int> conditions,
                                                 std::shared_ptr<const Extensions> base = nullptr,
                                                 std::vector<double> orbits = {});

}  // namespace opencnc::gcode
