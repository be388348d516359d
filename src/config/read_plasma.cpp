// SPDX-License-Identifier: GPL-3.0-or-later
// Reading [process.plasma] with its height control (.thc), its holes (.holes) and its simulated
// plate and arc (.sim): every key checked at its place (docs/cutting.md).
#include <fmt/format.h>

#include "sections.hpp"

namespace opencnc::config::detail {

/// A channel of `count` (an [io] count): within it, else an error at the key.
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

/// `value` (read from `key`) no faster than the torch axis allows.
void torch_within(Section& s, std::string_view key, double value, double limit, std::string_view of) {
  if (value > limit)
    s.error(key,
            fmt::format("{} ({}) is more than the torch axis' {} ({})", s.key_path(key), show(value), of,
                        show(limit)),
            "config.range");
}

namespace {

std::int32_t channel(Section& s, std::string_view key, int count, std::string_view what, int max) {
  return torch_channel(s, key, count, what, max);
}
void within(Section& s, std::string_view key, double value, double limit, std::string_view of) {
  torch_within(s, key, value, limit, of);
}

void read_thc(Section& s, MachineProfile& p, const AxisProfile* z) {
  machine::PlasmaConfig& c = p.plasma.config;
  const toml::table* t = s.subtable("thc");
  if (t == nullptr) return;
  Section m(*t, "process.plasma.thc",
            {"enabled", "delay_s", "speed_share", "volts_per_mm", "arc_voltage", "sample_s",
             "time_constant_s", "deadband_v", "filter_s", "max_velocity", "max_acceleration",
             "max_correction", "void_jump_v", "void_hold_s", "anti_dive_accel"},
            s.reporter());
  c.thc = m.boolean_or("enabled", true) ? 1 : 0;
  c.thc_delay_s = m.number_or("delay_s", c.thc_delay_s, Bound::NonNegative);
  c.speed_share = m.number_or("speed_share", c.speed_share, Bound::Positive);
  if (c.speed_share > 1)
    m.error("speed_share", "process.plasma.thc.speed_share is a share of the feed: at most 1",
            "config.range");
  c.volts_per_mm = m.number_or("volts_per_mm", c.volts_per_mm, Bound::Positive);
  c.arc_voltage_v = m.number_or("arc_voltage", c.arc_voltage_v, Bound::NonNegative);
  c.sample_s = m.number_or("sample_s", c.sample_s, Bound::Positive);
  c.time_constant_s = m.number_or("time_constant_s", c.time_constant_s, Bound::Positive);
  c.deadband_v = m.number_or("deadband_v", c.deadband_v, Bound::NonNegative);
  c.filter_s = m.number_or("filter_s", c.filter_s, Bound::NonNegative);
  c.max_velocity_mm_s = m.number_or("max_velocity", c.max_velocity_mm_s, Bound::Positive);
  c.max_accel_mm_s2 = m.number_or("max_acceleration", c.max_accel_mm_s2, Bound::Positive);
  c.max_correction_mm = m.number_or("max_correction", c.max_correction_mm, Bound::Positive);
  c.void_jump_v = m.number_or("void_jump_v", c.void_jump_v, Bound::Positive);
  c.void_hold_s = m.number_or("void_hold_s", c.void_hold_s, Bound::NonNegative);
  c.anti_dive_mm_s2 = m.number_or("anti_dive_accel", c.anti_dive_mm_s2, Bound::Positive);
  if (z != nullptr) {
    within(m, "max_velocity", c.max_velocity_mm_s, z->max_velocity, "max_velocity");
    within(m, "max_acceleration", c.max_accel_mm_s2, z->max_acceleration, "max_acceleration");
  }
}

void read_holes(Section& s, MachineProfile& p) {
  const toml::table* t = s.subtable("holes");
  if (t == nullptr) return;
  Section m(*t, "process.plasma.holes", {"diameter", "speed_share", "overcut", "arc_off"}, s.reporter());
  PlasmaHoles& h = p.plasma.holes;
  h.diameter_mm = m.number_or("diameter", h.diameter_mm, Bound::NonNegative);
  h.speed_share = m.number_or("speed_share", h.speed_share, Bound::Positive);
  if (h.speed_share > 1)
    m.error("speed_share", "process.plasma.holes.speed_share is a share of the feed: at most 1",
            "config.range");
  h.overcut_mm = m.number_or("overcut", h.overcut_mm, Bound::NonNegative);
  h.arc_off_mm = m.number_or("arc_off", h.arc_off_mm, Bound::NonNegative);
  if (h.arc_off_mm > 0 && h.overcut_mm == 0 && h.diameter_mm > 0 && h.arc_off_mm >= 3.14159 * h.diameter_mm)
    m.error("arc_off", "process.plasma.holes.arc_off is longer than the largest hole's circumference",
            "config.range");
}

void read_plasma_sim(Section& s, MachineProfile& p) {
  const toml::table* t = s.subtable("sim");
  if (t == nullptr) return;
  Section m(*t, "process.plasma.sim",
            {"seed", "plate_z", "warp", "warp_wavelength", "plate_min", "plate_max", "base_voltage",
             "volts_per_mm", "slow_volts", "full_speed", "kerf_width", "kerf_volts", "noise_v", "arc_delay_s",
             "transfer_height", "max_arc_height", "arc_losses_per_min", "sensor_noise"},
            s.reporter());
  machine::SimPlasmaConfig& c = p.plasma.sim;
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
            "process.plasma.sim.plate_max must lie beyond plate_min in X and Y, the plate at most 20 m²",
            "config.range");
  c.base_voltage_v = m.number_or("base_voltage", c.base_voltage_v, Bound::Positive);
  c.volts_per_mm = m.number_or("volts_per_mm", c.volts_per_mm, Bound::Positive);
  c.slow_volts_v = m.number_or("slow_volts", c.slow_volts_v, Bound::NonNegative);
  c.full_speed_mm_s = m.number_or("full_speed", c.full_speed_mm_s, Bound::Positive);
  c.kerf_width_mm = m.number_or("kerf_width", c.kerf_width_mm, Bound::Positive);
  c.kerf_volts_v = m.number_or("kerf_volts", c.kerf_volts_v, Bound::NonNegative);
  c.noise_v = m.number_or("noise_v", c.noise_v, Bound::NonNegative);
  c.arc_delay_s = m.number_or("arc_delay_s", c.arc_delay_s, Bound::NonNegative);
  c.transfer_height_mm = m.number_or("transfer_height", c.transfer_height_mm, Bound::Positive);
  c.max_arc_height_mm = m.number_or("max_arc_height", c.max_arc_height_mm, Bound::Positive);
  c.arc_losses_per_min = m.number_or("arc_losses_per_min", c.arc_losses_per_min, Bound::NonNegative);
  c.sensor_noise_mm = m.number_or("sensor_noise", c.sensor_noise_mm, Bound::NonNegative);
  const machine::PlasmaConfig& k = p.plasma.config;  // the torch's inputs are the plate's sensors
  c.arc_voltage_input = k.arc_voltage_input;
  c.sensor_input = k.sensor_input;
  c.sensor = k.sensor;
  c.switch_offset_mm = k.sensor == machine::PlateSensor::Float ? k.switch_offset_mm : 0.0;
  if (k.pierce_height_mm > c.transfer_height_mm)
    m.error(
        "transfer_height",
        fmt::format("process.plasma.sim.transfer_height ({}) is below the pierce height ({}): the arc would "
                    "never transfer",
                    show(c.transfer_height_mm), show(k.pierce_height_mm)),
        "config.range");
}

}  // namespace

void read_plasma(Section& process, MachineProfile& profile) {
  const toml::table* t = process.subtable("plasma");
  if (t == nullptr) return;
  Section s(*t, "process.plasma",
            {"arc_voltage_input",
             "sensor",
             "sensor_input",
             "switch_offset",
             "pierce_height",
             "pierce_delay_s",
             "puddle_height",
             "puddle_delay_s",
             "cut_height",
             "probe_speed",
             "probe_travel",
             "height_speed",
             "height_acceleration",
             "arc_ok_timeout_s",
             "arc_loss_s",
             "max_starts",
             "breakaway_input",
             "thc",
             "holes",
             "sim"},
            process.reporter());
  PlasmaProfile& pl = profile.plasma;
  machine::PlasmaConfig& c = pl.config;
  pl.present = true;
  c.enabled = 1;
  if (!profile.process.torch)
    s.error("sensor", "a [process.plasma] machine needs its torch: [process] torch = true", "config.range");
  const AxisProfile* z = profile.find(Axis::Z);
  if (z == nullptr)
    s.error("height_speed", "a [process.plasma] machine needs a Z axis: the torch's", "config.range");
  c.z_axis = index(Axis::Z);
  if (!s.has("arc_voltage_input")) s.missing("arc_voltage_input");
  if (!s.has("sensor_input")) s.missing("sensor_input");
  c.arc_voltage_input =
      channel(s, "arc_voltage_input", profile.io.analog_inputs, "analog input", machine::kAnalogChannels);
  c.sensor_input =
      channel(s, "sensor_input", profile.io.digital_inputs, "digital input", machine::kDigitalChannels);
  if (s.has("breakaway_input"))
    c.breakaway_input =
        channel(s, "breakaway_input", profile.io.digital_inputs, "digital input", machine::kDigitalChannels);
  c.sensor = s.choice<machine::PlateSensor>(
      "sensor", {{"float", machine::PlateSensor::Float}, {"ohmic", machine::PlateSensor::Ohmic}},
      machine::PlateSensor::Float);
  c.switch_offset_mm = s.number_or("switch_offset", c.switch_offset_mm, Bound::NonNegative);
  if (c.sensor == machine::PlateSensor::Ohmic) {
    s.reject("switch_offset",
             "ohmic contact touches the plate itself (sensor = \"float\" has a switch offset)");
    c.switch_offset_mm = 0;
  }
  c.pierce_height_mm = s.number_or("pierce_height", c.pierce_height_mm, Bound::Positive);
  c.pierce_delay_s = s.number_or("pierce_delay_s", c.pierce_delay_s, Bound::NonNegative);
  c.puddle_height_mm = s.number_or("puddle_height", c.puddle_height_mm, Bound::NonNegative);
  c.puddle_delay_s = s.number_or("puddle_delay_s", c.puddle_delay_s, Bound::NonNegative);
  c.cut_height_mm = s.number_or("cut_height", c.cut_height_mm, Bound::Positive);
  if (c.cut_height_mm > c.pierce_height_mm)
    s.error("cut_height",
            fmt::format("process.plasma.cut_height ({}) is above the pierce height ({})",
                        show(c.cut_height_mm), show(c.pierce_height_mm)),
            "config.range");
  if (c.puddle_height_mm == 0) s.reject("puddle_delay_s", "needs process.plasma.puddle_height");
  c.probe_speed_mm_s = s.number_or("probe_speed", c.probe_speed_mm_s, Bound::Positive);
  c.probe_travel_mm = s.number_or("probe_travel", c.probe_travel_mm, Bound::Positive);
  c.height_speed_mm_s = s.number_or("height_speed", c.height_speed_mm_s, Bound::Positive);
  c.height_accel_mm_s2 = s.number_or("height_acceleration", c.height_accel_mm_s2, Bound::Positive);
  c.arc_ok_timeout_s = s.number_or("arc_ok_timeout_s", c.arc_ok_timeout_s, Bound::Positive);
  c.arc_loss_s = s.number_or("arc_loss_s", c.arc_loss_s, Bound::NonNegative);
  c.max_starts = static_cast<std::int32_t>(s.integer("max_starts", 1, 100).value_or(c.max_starts));
  if (z != nullptr) {
    within(s, "probe_speed", c.probe_speed_mm_s, z->max_velocity, "max_velocity");
    within(s, "height_speed", c.height_speed_mm_s, z->max_velocity, "max_velocity");
    within(s, "height_acceleration", c.height_accel_mm_s2, z->max_acceleration, "max_acceleration");
  }
  read_thc(s, profile, z);
  read_holes(s, profile);
  read_plasma_sim(s, profile);
}

}  // namespace opencnc::config::detail
