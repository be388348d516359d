// SPDX-License-Identifier: GPL-3.0-or-later
// Reading [process.oxyfuel] with its height control (.thc) and its simulated plate (.sim): an
// oxy-fuel torch driven by the torch stage (preheat, cutting oxygen, a capacitive height sensor on
// the plasma's Z-offset channel), every key checked at its place (docs/cutting.md, "Oxy-fuel").
#include <fmt/format.h>

#include <algorithm>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

void read_oxy_thc(Section& s, MachineProfile& p, const AxisProfile* z) {
  machine::PlasmaConfig& c = p.plasma.config;
  const toml::table* t = s.subtable("thc");
  if (t == nullptr) return;
  Section m(*t, "process.oxyfuel.thc",
            {"enabled", "delay_s", "speed_share", "time_constant_s", "deadband", "filter_s", "max_velocity",
             "max_acceleration", "max_correction", "jump", "jump_hold_s", "anti_dive_accel"},
            s.reporter());
  read_thc_common(m, c, z);
  c.deadband_mm = m.number_or("deadband", c.deadband_mm, Bound::NonNegative);
  c.height_jump_mm = m.number_or("jump", c.height_jump_mm, Bound::Positive);
  c.void_hold_s = m.number_or("jump_hold_s", c.void_hold_s, Bound::NonNegative);
  if (c.height_jump_mm <= c.deadband_mm)
    m.error("jump",
            fmt::format("process.oxyfuel.thc.jump ({}) must be more than the deadband ({})",
                        show(c.height_jump_mm), show(c.deadband_mm)),
            "config.range");
}

void read_oxy_sim(Section& s, MachineProfile& p) {
  const toml::table* t = s.subtable("sim");
  if (t == nullptr) return;
  Section m(*t, "process.oxyfuel.sim",
            {"seed", "plate_z", "warp", "warp_wavelength", "plate_min", "plate_max", "kerf_width",
             "kerf_height", "height_noise"},
            s.reporter());
  machine::SimPlasmaConfig& c = p.plasma.sim;
  read_sim_plate(m, c);
  c.oxy_fuel = true;
  c.kerf_width_mm = m.number_or("kerf_width", 2.0, Bound::Positive);
  c.kerf_height_mm = m.number_or("kerf_height", c.kerf_height_mm, Bound::NonNegative);
  c.height_noise_mm = m.number_or("height_noise", c.height_noise_mm, Bound::NonNegative);
  const machine::PlasmaConfig& k = p.plasma.config;  // the torch's channels are the simulated sensor's
  c.height_input = k.height_input;
  c.cut_oxygen_output = k.cut_oxygen_output;
  c.sensor_volts_per_mm = k.sensor_volts_per_mm;
  c.sensor_zero_v = k.sensor_zero_v;
  c.sensor_range_mm = k.sensor_range_mm;
}

}  // namespace

void read_oxyfuel(Section& process, MachineProfile& profile) {
  const toml::table* t = process.subtable("oxyfuel");
  if (t == nullptr) return;
  Section s(*t, "process.oxyfuel",
            {"height_input", "sensor_volts_per_mm", "sensor_zero_v", "sensor_range", "cut_oxygen_output",
             "breakaway_input", "ignite_s", "preheat", "preheat_s", "preheat_height", "pierce_height",
             "pierce_delay_s", "cut_height", "probe_speed", "probe_travel", "height_speed",
             "height_acceleration", "thc", "sim"},
            process.reporter());
  PlasmaProfile& pl = profile.plasma;
  if (pl.present)
    s.error("height_input",
            "a machine has one torch: [process.plasma] and [process.oxyfuel] exclude each other",
            "config.range");
  machine::PlasmaConfig& c = pl.config;
  c = machine::PlasmaConfig{};
  pl.present = true;
  c.enabled = 1;
  c.process = machine::TorchProcess::OxyFuel;
  c.pierce_height_mm = 10;  // oxy-fuel's own defaults (docs/cutting.md, "Oxy-fuel")
  c.pierce_delay_s = 1;
  c.cut_height_mm = 7;
  c.void_hold_s = 0.1;
  c.time_constant_s = 0.05;
  c.max_velocity_mm_s = 20;
  c.max_accel_mm_s2 = 500;
  if (!profile.process.torch)
    s.error("height_input", "a [process.oxyfuel] machine needs its torch: [process] torch = true",
            "config.range");
  const AxisProfile* z = profile.find(Axis::Z);
  if (z == nullptr)
    s.error("height_speed", "a [process.oxyfuel] machine needs a Z axis: the torch's", "config.range");
  c.z_axis = index(Axis::Z);
  for (const auto& [key, what] : {std::pair<std::string_view, std::string_view>{
                                      "height_input", "its capacitive height sensor's analog input"},
                                  {"sensor_volts_per_mm", "its height sensor's volts per mm"},
                                  {"cut_oxygen_output", "its cutting oxygen valve's digital output"}})
    if (!s.has(key))
      s.error(
          key,
          fmt::format("[process.oxyfuel] needs {} ({}): the oxy-fuel torch's height control and cut depend "
                      "on it",
                      key, what),
          "config.missing-key");
  c.height_input =
      torch_channel(s, "height_input", profile.io.analog_inputs, "analog input", machine::kAnalogChannels);
  c.cut_oxygen_output = torch_channel(s, "cut_oxygen_output", profile.io.digital_outputs, "digital output",
                                      machine::kDigitalChannels);
  if (s.has("breakaway_input"))
    c.breakaway_input = torch_channel(s, "breakaway_input", profile.io.digital_inputs, "digital input",
                                      machine::kDigitalChannels);
  c.sensor_volts_per_mm = s.number_or("sensor_volts_per_mm", c.sensor_volts_per_mm, Bound::Positive);
  c.sensor_zero_v = s.number_or("sensor_zero_v", c.sensor_zero_v);
  c.sensor_range_mm = s.number_or("sensor_range", c.sensor_range_mm, Bound::Positive);
  c.ignite_s = s.number_or("ignite_s", c.ignite_s, Bound::NonNegative);
  c.preheat = s.choice<machine::PreheatMode>(
      "preheat", {{"time", machine::PreheatMode::Time}, {"operator", machine::PreheatMode::Operator}},
      machine::PreheatMode::Time);
  c.preheat_s = s.number_or("preheat_s", c.preheat_s, Bound::NonNegative);
  c.preheat_height_mm = s.number_or("preheat_height", c.preheat_height_mm, Bound::Positive);
  c.pierce_height_mm = s.number_or("pierce_height", c.pierce_height_mm, Bound::Positive);
  c.pierce_delay_s = s.number_or("pierce_delay_s", c.pierce_delay_s, Bound::NonNegative);
  read_cut_height(s, c);
  const double highest = std::max({c.preheat_height_mm, c.pierce_height_mm, c.cut_height_mm});
  if (highest >= c.sensor_range_mm)
    s.error("sensor_range",
            fmt::format("process.oxyfuel.sensor_range ({} mm) must reach above the preheat, pierce and cut "
                        "heights (up to {} mm): the sensor reads the height there",
                        show(c.sensor_range_mm), show(highest)),
            "config.range");
  read_torch_motion(s, c, z);
  read_oxy_thc(s, profile, z);
  read_oxy_sim(s, profile);
}

}  // namespace opencnc::config::detail
