// SPDX-License-Identifier: GPL-3.0-or-later
// [process.broaching]: the broach's load cell, the levels that hold or retract, the process-data
// log's rate, and [process.broaching.sim], the bore and cutter the simulated load comes from.
#include <fmt/format.h>

#include <cmath>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

/// Plausible bounds: a broach's cutting force is kN to a few hundred kN; a log faster than the
/// servo period would repeat rows.
constexpr double kMaxLoadKn = 10000;

void read_levels(Section& s, BroachingProfile& b, const MachineProfile& p) {
  const auto input = s.integer("load_input", 0, machine::kAnalogChannels - 1);
  if (input && *input >= p.io.analog_inputs)
    s.error("load_input",
            fmt::format(
                "process.broaching.load_input is analog input {}, but the machine has {} (io.analog_inputs)",
                *input, p.io.analog_inputs),
            "config.range");
  if (!s.has("load_input")) s.missing("load_input");
  b.load_input = static_cast<int>(input.value_or(0));
  b.hold_kn = s.number_or("hold_kn", 0, Bound::Positive);
  b.retract_kn = s.number_or("retract_kn", 0, Bound::Positive);
  for (const std::string_view key : {"hold_kn", "retract_kn"}) {
    const double v = key == "hold_kn" ? b.hold_kn : b.retract_kn;
    if (v > kMaxLoadKn)
      s.error(key,
              fmt::format("{} must be at most {} kN (it is {})", s.key_path(key), show(kMaxLoadKn), show(v)),
              "config.range");
  }
  if (!s.has("hold_kn") && !s.has("retract_kn")) s.missing("hold_kn");
  if (b.hold_kn > 0 && b.retract_kn > 0 && b.retract_kn <= b.hold_kn)
    s.error("retract_kn",
            fmt::format("process.broaching.retract_kn ({}) must be above hold_kn ({})", show(b.retract_kn),
                        show(b.hold_kn)),
            "config.limits");
  b.confirm_s = s.number_or("confirm_s", b.confirm_s, Bound::NonNegative);
  if (b.confirm_s > 1)
    s.error("confirm_s",
            fmt::format("process.broaching.confirm_s must be at most 1 s (it is {})", show(b.confirm_s)),
            "config.range");
}

void read_retract(Section& s, BroachingProfile& b, const MachineProfile& p) {
  if (const auto word = s.string("radial_axis")) {
    const auto axis = axis_from_letter(*word);
    const AxisProfile* a = axis ? p.find(*axis) : nullptr;
    if (a == nullptr || a->rotary || a->manual() ||
        (p.coupling.present && (*axis == p.coupling.master || *axis == p.coupling.slave))) {
      s.error("radial_axis",
              fmt::format(
                  "process.broaching.radial_axis must name a driven linear axis of this machine other than "
                  "the coupled ones (it is \"{}\")",
                  *word),
              "config.range");
    } else {
      b.radial = *axis;
    }
  } else if (p.find(b.radial) == nullptr) {
    s.missing("radial_axis");
  }
  b.retract_lift = s.number_or("retract_lift", b.retract_lift);
  if (b.retract_lift == 0 || std::fabs(b.retract_lift) > 1000)
    s.error("retract_lift",
            fmt::format(
                "process.broaching.retract_lift must be a signed distance, not 0, within ±1000 mm (it is {})",
                show(b.retract_lift)),
            "config.range");
  b.retract_speed = s.number_or("retract_speed", 0, Bound::NonNegative);
  b.log_rate_hz = s.number_or("log_rate_hz", b.log_rate_hz, Bound::Positive);
  if (b.log_rate_hz * p.servo_period_s > 1.0 + 1e-9)
    s.error("log_rate_hz",
            fmt::format(
                "process.broaching.log_rate_hz must be at most one row per servo period ({} Hz; it is {})",
                show(1 / p.servo_period_s), show(b.log_rate_hz)),
            "config.range");
}

// The bore on the coupling's axes: the stroke is its master, the workpiece its slave.
void read_bore(Section& broaching, BroachingProfile& b, const MachineProfile& p) {
  const toml::table* t = broaching.subtable("sim");
  if (t == nullptr) return;
  Section s(*t, "process.broaching.sim",
            {"bore_start", "bore_end", "surface", "specific_force_n_mm2", "width_mm", "speed_gain_per_m_min",
             "min_speed", "dull_factor", "noise_kn", "load_on_stroke"},
            broaching.reporter());
  machine::SimBroachConfig& m = b.sim;
  m.present = true;
  if (!p.coupling.present)
    broaching.error(
        "sim", "process.broaching.sim needs [coupling]: the stroke is its master, the workpiece its slave",
        "config.missing-key");
  m.bore_start = s.required_number("bore_start");
  m.bore_end = s.required_number("bore_end");
  if (s.has("bore_start") && s.has("bore_end") && !(m.bore_end > m.bore_start))
    s.error("bore_end",
            fmt::format("process.broaching.sim.bore_end ({}) must be beyond bore_start ({})",
                        show(m.bore_end), show(m.bore_start)),
            "config.limits");
  m.surface = s.number_or("surface", 0);
  m.specific_force_n_mm2 = s.number_or("specific_force_n_mm2", m.specific_force_n_mm2, Bound::Positive);
  m.width_mm = s.number_or("width_mm", m.width_mm, Bound::Positive);
  m.speed_gain_per_m_min = s.number_or("speed_gain_per_m_min", m.speed_gain_per_m_min, Bound::NonNegative);
  m.min_speed_mm_s = s.number_or("min_speed", m.min_speed_mm_s, Bound::NonNegative);
  m.dull_factor = s.number_or("dull_factor", m.dull_factor, Bound::Positive);
  m.noise_kn = s.number_or("noise_kn", m.noise_kn, Bound::NonNegative);
  m.load_on_stroke = s.boolean_or("load_on_stroke", false);
  m.load_input = b.load_input;
  m.radius_mm = p.coupling.radius_mm;
}

}  // namespace

void read_broaching(Section& process, MachineProfile& profile) {
  const toml::table* t = process.subtable("broaching");
  if (t == nullptr) return;
  Section s(*t, "process.broaching",
            {"load_input", "hold_kn", "retract_kn", "confirm_s", "radial_axis", "retract_lift",
             "retract_speed", "log_rate_hz", "sim"},
            process.reporter());
  BroachingProfile& b = profile.broaching;
  b.present = true;
  read_levels(s, b, profile);
  read_retract(s, b, profile);
  read_bore(s, b, profile);
}

}  // namespace opencnc::config::detail
