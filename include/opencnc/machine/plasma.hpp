// SPDX-License-Identifier: GPL-3.0-or-later
// Plasma cutting as plain data for the tick and the simulated machine: the torch's sequence per
// cut, its torch height control and the simulated process (the profile's [process.plasma],
// docs/cutting.md).
#pragma once

#include <cstdint>
#include <type_traits>

namespace opencnc::machine {

/// The codes of a plasma cut (LinuxCNC user M codes, M100–M199 take P and Q): torch on — find
/// the plate, pierce, go to the cut height, cut under height control — and torch off (retract);
/// the height control held (`M192`, a hole or a small feature) and let go again (`M193`).
inline constexpr int kTorchOnCode = 190;
inline constexpr int kTorchOffCode = 191;
inline constexpr int kThcHoldCode = 192;
inline constexpr int kThcReleaseCode = 193;

/// What finds the plate's top: the torch's float switch (it trips once the torch has pushed the
/// float up by `switch_offset_mm`) or ohmic contact (the nozzle touching the plate).
enum class PlateSensor : std::int32_t { Float = 0, Ohmic = 1 };

/// Which torch the stage drives: a plasma arc (arc voltage, arc-OK, float switch or ohmic
/// contact) or an oxy-fuel flame (a capacitive height sensor, preheat, cutting oxygen; no arc).
enum class TorchProcess : std::int32_t { Plasma = 0, OxyFuel = 1 };

/// How an oxy-fuel preheat ends: after `preheat_s` (the operator's start may cut it short), or
/// only at the operator's start (CommandKind::StartCut: the steel glows, the operator says so).
enum class PreheatMode : std::int32_t { Time = 0, Operator = 1 };

/// The torch's sequence and its height control, as the tick runs them (control::TorchHeight).
/// Heights are above the plate's top, mm; every double first, then 32-bit integers in pairs: no
/// padding, so that equal settings are equal bytes (control::shared_setup).
struct PlasmaConfig {
  // The sequence of a cut.
  double pierce_height_mm = 3.8;     ///< the torch fires this high above the plate
  double pierce_delay_s = 0.5;       ///< and stands there this long once the arc is established
  double puddle_height_mm = 0;       ///< after the pierce, move off at this height (0: no puddle jump)
  double puddle_delay_s = 0;         ///< … for this long, then down to the cut height
  double cut_height_mm = 1.5;        ///< the height the cut holds
  double switch_offset_mm = 1.5;     ///< the float's travel before its switch trips (ohmic: 0)
  double probe_speed_mm_s = 20;      ///< down to the plate
  double probe_travel_mm = 60;       ///< most travel below the programmed height before a probe fails
  double height_speed_mm_s = 50;     ///< moves between heights (up from the plate, pierce to cut, retract)
  double height_accel_mm_s2 = 2000;  ///< their acceleration (and the probe's)
  double arc_ok_timeout_s = 3;       ///< torch on to arc-OK before a start has failed
  double arc_loss_s = 0.005;         ///< arc-OK off this long while cutting: the arc is lost
  // Torch height control (THC).
  double thc_delay_s = 0.2;       ///< at the cut height and up to speed this long before THC acts
  double speed_share = 0.9;       ///< THC acts only at this share of the programmed feed or above
  double volts_per_mm = 7.5;      ///< how much the arc voltage rises per mm of height
  double arc_voltage_v = 0;       ///< the voltage to hold; 0: sampled when THC begins (auto volts)
  double sample_s = 0.05;         ///< the auto-volts sample's length (mean of the filtered voltage)
  double time_constant_s = 0.03;  ///< a height error is corrected with this time constant
  double deadband_v = 0.3;        ///< no correction within this much of the target
  double filter_s = 0.003;        ///< the arc voltage's low-pass time constant
  double max_velocity_mm_s = 40;  ///< the correction's speed …
  double max_accel_mm_s2 = 1500;  ///< … and acceleration
  double max_correction_mm = 10;  ///< the correction's limit either way from the probed height
  double void_jump_v = 5;         ///< a voltage this far from the target holds (kerf crossing, void)
  double void_hold_s = 0.08;      ///< and holds this long after it is back within
  double anti_dive_mm_s2 = 100;   ///< the path braking harder than this holds (anti-dive)
  // Oxy-fuel ([process.oxyfuel]): the flame's sequence and the capacitive height sensor.
  double preheat_height_mm = 7;      ///< the flame preheats the plate this high above it
  double preheat_s = 4;              ///< preheat by time: this long (0: straight to the pierce)
  double ignite_s = 0.5;             ///< torch on (fuel gas, preheat oxygen, spark) to a lit flame
  double sensor_volts_per_mm = 0.5;  ///< the height sensor's reading per mm of height (V/mm)
  double sensor_zero_v = 0;          ///< its reading at zero height (V)
  double sensor_range_mm = 25;       ///< heights above this are out of its range (no plate under it)
  double height_jump_mm = 1;         ///< the measured height this far from the cut height holds
  double deadband_mm = 0.04;         ///< no correction within this much of the cut height
  // Inputs, the torch axis, limits.
  std::int32_t arc_voltage_input = 0;  ///< analog input of the arc voltage (divided), V
  std::int32_t sensor_input = 0;       ///< digital input of the float switch or ohmic contact
  PlateSensor sensor = PlateSensor::Float;
  std::int32_t z_axis = 2;      ///< the torch axis (Z)
  std::int32_t max_starts = 3;  ///< failed starts in a row before the run is held
  std::int32_t enabled = 0;     ///< 1: the machine has [process.plasma]
  std::int32_t thc = 1;         ///< 0: the height stays where the probe put it (no THC)
  std::int32_t breakaway_input = -1;  ///< digital input of the torch's breakaway switch (-1: none)
  TorchProcess process = TorchProcess::Plasma;
  PreheatMode preheat = PreheatMode::Time;
  std::int32_t height_input = 0;        ///< oxy-fuel: analog input of the capacitive height sensor, V
  std::int32_t cut_oxygen_output = -1;  ///< oxy-fuel: digital output of the cutting oxygen valve
  bool oxy_fuel() const noexcept { return process == TorchProcess::OxyFuel; }
};

static_assert(std::is_trivially_copyable_v<PlasmaConfig>);
static_assert(sizeof(PlasmaConfig) == 34 * sizeof(double) + 12 * sizeof(std::int32_t),
              "PlasmaConfig must have no padding (shared_setup compares set-ups byte for byte)");

/// The simulated plate and arc (`[process.plasma.sim]`, docs/cutting.md): a warped plate whose
/// top is a smooth deterministic surface, the arc voltage from the height and the speed, kerfs
/// already cut, noise and arc losses. Positions are the joints' (machine coordinates of a table
/// homed at its power-up position).
struct SimPlasmaConfig {
  bool present = false;
  std::int8_t x_joint = 0, y_joint = 1, z_joint = 2;
  std::uint64_t seed = 1;           ///< the surface's phases, the noise and random losses
  double plate_z_mm = 0;            ///< the plate's mean top
  double warp_mm = 0;               ///< the surface's amplitude (± this much about plate_z_mm)
  double warp_wavelength_mm = 900;  ///< its shortest wavelength
  double plate_min[2] = {0, 0};     ///< the plate's extent in X and Y (kerfs are kept over it)
  double plate_max[2] = {1250, 2500};
  double base_voltage_v = 100;  ///< the arc voltage at zero height and full speed
  double volts_per_mm = 7.5;    ///< per mm of height
  double slow_volts_v = 6;      ///< more at a standstill than at `full_speed_mm_s` (a wider kerf)
  double full_speed_mm_s = 40;
  double kerf_width_mm = 1.5;     ///< the width each cut leaves
  double kerf_volts_v = 25;       ///< the voltage's jump while the arc crosses a kerf
  double noise_v = 0.5;           ///< ± uniform noise of the measured voltage
  double arc_delay_s = 0.3;       ///< torch on to arc-OK (the arc transferred to the plate)
  double transfer_height_mm = 8;  ///< the pilot arc transfers only from this height or lower
  double max_arc_height_mm = 12;  ///< the arc goes out above this
  double arc_losses_per_min = 0;  ///< random losses per minute of arc time
  double sensor_noise_mm = 0.01;  ///< ± uniform noise of the switching point
  PlateSensor sensor = PlateSensor::Float;
  double switch_offset_mm = 1.5;  ///< the float's travel before its switch trips
  std::int32_t arc_voltage_input = 0, sensor_input = 0;
  // Oxy-fuel ([process.oxyfuel.sim]): no arc; the flame burns while the torch output is on, the
  // cutting oxygen (its digital output) cuts the kerf; a capacitive height sensor reads the height.
  bool oxy_fuel = false;
  std::int32_t height_input = 0, cut_oxygen_output = -1;
  double sensor_volts_per_mm = 0.5, sensor_zero_v = 0, sensor_range_mm = 25;
  double height_noise_mm = 0.02;  ///< ± uniform noise of the sensed height
  double kerf_height_mm = 2;      ///< the sensor reads this much higher over a kerf (less steel under it)
};

}  // namespace opencnc::machine
