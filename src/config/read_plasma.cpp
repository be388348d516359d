// SPDX-License-Identifier: GPL-3.0-or-later
// Reading [process.plasma] with its height control (.thc), its holes (.holes) and its simulated
// plate and arc (.sim): every key checked at its place (docs/cutting.md).
#include <fmt/format.h>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

void read_thc(Section& s, MachineProfile& p, const AxisProfile* z) {
  machine::PlasmaConfig& c = p.plasma.config;
  const toml::table* t = s.subtable("thc");
  if (t == nullptr) return;
  Section m(*t, "process.plasma.thc",
            {"enabled", "delay_s", "speed_share", "volts_per_mm", "arc_voltage", "sample_s",
             "time_constant_s", "deadband_v", "filter_s", "max_velocity", "max_acceleration",
             "max_correction", "void_jump_v", "void_hold_s", "anti_dive_accel"},
            s.reporter());
  read_thc_common(m, c, z);
  c.volts_per_mm = m.number_or("volts_per_mm", c.volts_per_mm, Bound::Positive);
  c.arc_voltage_v = m.number_or("arc_voltage", c.arc_voltage_v, Bound::NonNegative);
  c.sample_s = m.number_or("sample_s", c.sample_s, Bound::Positive);
  c.deadband_v = m.number_or("deadband_v", c.deadband_v, Bound::NonNegative);
  c.void_jump_v = m.number_or("void_jump_v", c.void_jump_v, Bound::Positive);
  c.void_hold_s = m.number_or("void_hold_s", c.void_hold_s, Bound::NonNegative);
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
  read_sim_plate(m, c);
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
  c.arc_voltage_input = torch_channel(s, "arc_voltage_input", profile.io.analog_inputs, "analog input",
                                      machine::kAnalogChannels);
  c.sensor_input =
      torch_channel(s, "sensor_input", profile.io.digital_inputs, "digital input", machine::kDigitalChannels);
  if (s.has("breakaway_input"))
    c.breakaway_input = torch_channel(s, "breakaway_input", profile.io.digital_inputs, "digital input",
                                      machine::kDigitalChannels);
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
  read_cut_height(s, c);
  if (c.puddle_height_mm == 0) s.reject("puddle_delay_s", "needs process.plasma.puddle_height");
  read_torch_motion(s, c, z);
  c.arc_ok_timeout_s = s.number_or("arc_ok_timeout_s", c.arc_ok_timeout_s, Bound::Positive);
  c.arc_loss_s = s.number_or("arc_loss_s", c.arc_loss_s, Bound::NonNegative);
  c.max_starts = static_cast<std::int32_t>(s.integer("max_starts", 1, 100).value_or(c.max_starts));
  read_thc(s, profile, z);
  read_holes(s, profile);
  read_plasma_sim(s, profile);
}

}  // namespace opencnc::config::detail
