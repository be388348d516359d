// SPDX-License-Identifier: GPL-3.0-or-later
// What [process.plasma] and [process.oxyfuel] read alike: the torch's channels, its Z motion, its
// heights, the height control's common keys and the simulated plate (sections.hpp).
#include <fmt/format.h>

#include "sections.hpp"

namespace opencnc::config::detail {

std::int32_t torch_channel(Section& s, std::string_view key, int count, std::string_view what, int max) {
  const auto v = s.integer(key, 0, max - 1);
  if (v && *v >= count)
    s.error(key,
            fmt::format("{} is {} {}, but the machine has {} ({})", s.key_path(key), what, *v, count,
                        what == "analog input"     ? "io.analog_inputs"
                        : what == "digital output" ? "io.digital_outputs"
                                                   : "io.digital_inputs"),
            "config.range");
  return static_cast<std::int32_t>(v.value_or(0));
}

void torch_within(Section& s, std::string_view key, double value, double limit, std::string_view of) {
  if (value > limit)
    s.error(key,
            fmt::format("{} ({}) is more than the torch axis' {} ({})", s.key_path(key), show(value), of,
                        show(limit)),
            "config.range");
}

void read_torch_motion(Section& s, machine::PlasmaConfig& c, const AxisProfile* z) {
  c.probe_speed_mm_s = s.number_or("probe_speed", c.probe_speed_mm_s, Bound::Positive);
  c.probe_travel_mm = s.number_or("probe_travel", c.probe_travel_mm, Bound::Positive);
  c.height_speed_mm_s = s.number_or("height_speed", c.height_speed_mm_s, Bound::Positive);
  c.height_accel_mm_s2 = s.number_or("height_acceleration", c.height_accel_mm_s2, Bound::Positive);
  if (z != nullptr) {
    torch_within(s, "probe_speed", c.probe_speed_mm_s, z->max_velocity, "max_velocity");
    torch_within(s, "height_speed", c.height_speed_mm_s, z->max_velocity, "max_velocity");
    torch_within(s, "height_acceleration", c.height_accel_mm_s2, z->max_acceleration, "max_acceleration");
  }
}

void read_cut_height(Section& s, machine::PlasmaConfig& c) {
  c.cut_height_mm = s.number_or("cut_height", c.cut_height_mm, Bound::Positive);
  if (c.cut_height_mm > c.pierce_height_mm)
    s.error("cut_height",
            fmt::format("{} ({}) is above the pierce height ({})", s.key_path("cut_height"),
                        show(c.cut_height_mm), show(c.pierce_height_mm)),
            "config.range");
}

void read_thc_common(Section& m, machine::PlasmaConfig& c, const AxisProfile* z) {
  c.thc = m.boolean_or("enabled", true) ? 1 : 0;
  c.thc_delay_s = m.number_or("delay_s", c.thc_delay_s, Bound::NonNegative);
  c.speed_share = m.number_or("speed_share", c.speed_share, Bound::Positive);
  if (c.speed_share > 1)
    m.error("speed_share", fmt::format("{} is a share of the feed: at most 1", m.key_path("speed_share")),
            "config.range");
  c.time_constant_s = m.number_or("time_constant_s", c.time_constant_s, Bound::Positive);
  c.filter_s = m.number_or("filter_s", c.filter_s, Bound::NonNegative);
  c.max_velocity_mm_s = m.number_or("max_velocity", c.max_velocity_mm_s, Bound::Positive);
  c.max_accel_mm_s2 = m.number_or("max_acceleration", c.max_accel_mm_s2, Bound::Positive);
  c.max_correction_mm = m.number_or("max_correction", c.max_correction_mm, Bound::Positive);
  c.anti_dive_mm_s2 = m.number_or("anti_dive_accel", c.anti_dive_mm_s2, Bound::Positive);
  if (z != nullptr) {
    torch_within(m, "max_velocity", c.max_velocity_mm_s, z->max_velocity, "max_velocity");
    torch_within(m, "max_acceleration", c.max_accel_mm_s2, z->max_acceleration, "max_acceleration");
  }
}

void read_sim_plate(Section& m, machine::SimPlasmaConfig& c) {
  c.present = true;
  c.seed = static_cast<std::uint64_t>(m.integer("seed", 0, INT64_MAX).value_or(1));
  c.plate_z_mm = m.number_or("plate_z", c.plate_z_mm);
  c.warp_mm = m.number_or("warp", c.warp_mm, Bound::NonNegative);
  c.warp_wavelength_mm = m.number_or("warp_wavelength", c.warp_wavelength_mm, Bound::Positive);
  for (const auto& [key, out] : {std::pair<std::string_view, double*>{"plate_min", c.plate_min},
                                 std::pair<std::string_view, double*>{"plate_max", c.plate_max}}) {
    const toml::node* n = m.find(key);
    if (n == nullptr) continue;
    const auto xy = number_pair(*n);
    if (!xy) {
      m.error(key, fmt::format("{} must be [X, Y] in mm", m.key_path(key)), "config.type");
      continue;
    }
    out[0] = xy->first;
    out[1] = xy->second;
  }
  if (c.plate_max[0] <= c.plate_min[0] || c.plate_max[1] <= c.plate_min[1] ||
      (c.plate_max[0] - c.plate_min[0]) * (c.plate_max[1] - c.plate_min[1]) > 2e7)
    m.error("plate_max",
            fmt::format("{} must lie beyond plate_min in X and Y, the plate at most 20 m²",
                        m.key_path("plate_max")),
            "config.range");
}

}  // namespace opencnc::config::detail
