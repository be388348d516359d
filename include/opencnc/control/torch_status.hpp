// SPDX-License-Identifier: GPL-3.0-or-later
// TorchStatus — the plasma torch's sequence and height control in the status snapshot and every
// trace sample (docs/cutting.md).
#pragma once

#include <cstdint>
#include <type_traits>

namespace opencnc::control {

/// Where a cut's sequence stands (control::TorchHeight).
enum class TorchPhase : std::uint8_t {
  Off,         ///< the torch is off and at the programmed height
  Probing,     ///< down to the plate until the float switch or ohmic contact
  ToPierce,    ///< up to the pierce height
  Igniting,    ///< torch on, waiting for arc-OK (oxy-fuel: for the flame, ignite_s)
  Piercing,    ///< the pierce delay
  Puddle,      ///< the puddle jump: moving off at the puddle height
  ToCut,       ///< down to the cut height
  Cutting,     ///< at the cut height, under height control
  Retracting,  ///< torch off, back to the programmed height
  Paused,      ///< held (the operator, an arc loss): torch off; a resume pierces again here
  Failed,      ///< no plate found, or too many failed starts: the run is held
  Preheating,  ///< oxy-fuel: the flame heats the plate (by time, or until the operator's start)
};

/// What the height control does in a period.
enum class ThcState : std::uint8_t {
  Off,          ///< not cutting (or THC off in the profile)
  Waiting,      ///< cutting, before the delay and the speed let it act
  Sampling,     ///< measuring the voltage to hold (auto volts)
  Active,       ///< correcting the height from the arc voltage
  CornerLock,   ///< held: the path is below the share of its feed
  AntiDive,     ///< held: the path brakes
  VoidLock,     ///< held: the voltage jumped (a kerf crossing, a void)
  ProgramLock,  ///< held by the program (M192: a hole, a small feature)
};

/// What the torch stage told the tick's events (EventKind::Torch, `action`).
enum class TorchEvent : std::uint8_t {
  ArcLost,          ///< arc-OK went off while cutting: torch off, feed hold
  StartFailed,      ///< no arc-OK within the timeout; `value` = starts failed in a row
  StartsExhausted,  ///< too many failed starts: feed hold
  PlateNotFound,    ///< the probe went its whole travel without the switch: feed hold
  Breakaway,        ///< the torch's breakaway switch (it hit something): torch off, feed hold
  FloatTripped,     ///< the float switch while the torch burns (it touched the plate): torch off, feed hold
  PreheatWaits,     ///< oxy-fuel: the preheat waits for the operator's start (StartCut)
  CutStarted,       ///< oxy-fuel: the preheat ended (`value`: its seconds); cutting oxygen on
};

struct TorchStatus {
  TorchPhase phase = TorchPhase::Off;
  ThcState thc = ThcState::Off;
  bool torch_on = false;          ///< the torch output
  bool arc_ok = false;            ///< the arc-OK input
  bool sensor = false;            ///< the float switch or ohmic contact input
  bool thc_hold = false;          ///< the program holds the height (M192)
  double arc_voltage_v = 0;       ///< measured this period
  double filtered_voltage_v = 0;  ///< after the low-pass filter
  double target_voltage_v = 0;    ///< the voltage held (0: not known yet)
  double thc_offset_mm = 0;       ///< the Z offset on top of the programmed path (every part of it)
  double correction_mm = 0;       ///< of it, the height control's correction since the cut height
  double plate_z_mm = 0;          ///< the plate's top where it was last found (machine Z)
  double cut_z_mm = 0;            ///< the Z the cut height is at there
  std::uint32_t pierces = 0;      ///< pierces begun (arc established) since the machine started
  std::uint32_t arc_losses = 0;   ///< arcs lost while cutting
  std::uint32_t failed_starts = 0;
  std::uint32_t breakaways = 0;   ///< breakaway switch trips during a cut
  std::uint32_t float_trips = 0;  ///< float switch trips while the torch burned
  // Oxy-fuel.
  bool oxy_fuel = false;        ///< the torch is a flame (no arc: arc-OK and voltages unused)
  bool cut_oxygen = false;      ///< the cutting oxygen output
  bool waiting_start = false;   ///< the preheat waits for the operator's start
  double sensor_height_mm = 0;  ///< the capacitive sensor's height, filtered (mm; its range when out of it)
  double preheat_s = 0;         ///< this (or the last) preheat so far
  double preheat_total_s = 0;   ///< every preheat since the machine started
  std::uint32_t preheats = 0;   ///< preheats begun
  std::uint32_t operator_starts = 0;  ///< preheats ended by the operator's start
};

static_assert(std::is_trivially_copyable_v<TorchStatus>);

}  // namespace opencnc::control
