// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart's codes as the tick sees them: `M194 P<n>` selects material n in the program; the
// interpreter's module turns it into one process code per torch setting the chart gives (its
// value in P), applied by the torch stage at an exact stop of no time (docs/cutting.md).
#pragma once

namespace opencnc::machine {

/// `M194 P<material>`: the program selects a cut chart material (a LinuxCNC user M code).
inline constexpr int kMaterialCode = 194;

/// The torch settings a material sets (process codes beyond the M range: only the module makes
/// them; each its own modal group, so a program resumed at segment k gets the values in force
/// there). P = the value in the chart's unit (mm, s, V).
inline constexpr int kChartPierceHeightCode = 1941;
inline constexpr int kChartPierceDelayCode = 1942;
inline constexpr int kChartCutHeightCode = 1943;
inline constexpr int kChartArcVoltageCode = 1944;  ///< 0: the profile's (auto volts when that is 0)
inline constexpr int kChartPuddleHeightCode = 1945;
inline constexpr int kChartPuddleDelayCode = 1946;
inline constexpr int kChartPreheatCode = 1947;  ///< oxy-fuel's preheat time; 0: the profile's

}  // namespace opencnc::machine
