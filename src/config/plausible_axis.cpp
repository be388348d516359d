// SPDX-License-Identifier: GPL-3.0-or-later
// Physically plausible axis limits: a value far outside what any machine has is a typo or a unit
// mix-up, and would make the planner wait for ever (1e-300 mm/s) or the numbers overflow (1e300).
#include <fmt/format.h>

#include <array>
#include <cmath>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

/// A range no real machine leaves, for linear axes (mm) and rotary axes (degrees).
struct Plausible {
  std::string_view key;
  std::string_view what;
  double min_linear, max_linear, min_rotary, max_rotary;
  std::string_view unit_linear, unit_rotary;
};

// From a watchmaker's lathe to a gantry on linear motors, with a margin of ten either way:
// 1 µm/s creep to 100 m/s, 1 µm/s² to 1000 g, jerk from 1 µm/s³ to 1e12 mm/s³; travel within
// ±1000 km. Rotary axes may turn ten times faster (spindle-like tables).
constexpr std::array<Plausible, 3> kDynamics{{
    {"max_velocity", "a velocity limit", 1e-3, 1e5, 1e-3, 1e6, "mm/s", "deg/s"},
    {"max_acceleration", "an acceleration limit", 1e-3, 1e7, 1e-3, 1e8, "mm/s²", "deg/s²"},
    {"max_jerk", "a jerk limit (0: none)", 1e-3, 1e12, 1e-3, 1e13, "mm/s³", "deg/s³"},
}};
constexpr double kMaxTravel = 1e9;  // mm or degrees from the origin

}  // namespace

void check_plausible(Section& s, const AxisProfile& a) {
  const double values[] = {a.max_velocity, a.max_acceleration, a.max_jerk};
  for (std::size_t i = 0; i < kDynamics.size(); ++i) {
    const Plausible& p = kDynamics[i];
    const double v = values[i];
    // 0 is a value already reported (or, for jerk, "no limit").
    if (!s.has(p.key) || v == 0) continue;
    const double lo = a.rotary ? p.min_rotary : p.min_linear, hi = a.rotary ? p.max_rotary : p.max_linear;
    if (v >= lo && v <= hi) continue;
    s.error(
        p.key,
        fmt::format("{} = {} is no plausible value: {} goes from {:g} to {:g} {} (a typo, or another unit?)",
                    s.key_path(p.key), show(v), p.what, lo, hi, a.rotary ? p.unit_rotary : p.unit_linear),
        "config.implausible");
  }
  if (a.wrapped) return;
  for (const std::string_view key : {"min_limit", "max_limit"}) {
    const double v = key == "min_limit" ? a.min_limit : a.max_limit;
    if (!s.has(key) || std::fabs(v) <= kMaxTravel) continue;
    s.error(key,
            fmt::format("{} = {} is no plausible value: soft limits lie within {:g} {} of the origin",
                        s.key_path(key), show(v), kMaxTravel, a.rotary ? "degrees" : "mm"),
            "config.implausible");
  }
}

}  // namespace opencnc::config::detail
