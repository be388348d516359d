// SPDX-License-Identifier: GPL-3.0-or-later
// HalMachine — MachineIO over LinuxCNC HAL pins: the servo tick's inputs read from the pins the HAL
// file nets to drivers (encoders, step generators, Mesa cards, parallel ports), its outputs written
// to them. The pins are plain pointers of HAL's own types, so this compiles and is tested without
// HAL; the component (src/hal/component.cpp) creates them.
#pragma once

#include <array>
#include <cstdint>

#include "opencnc/control/heartbeat.hpp"
#include "opencnc/machine/machine_io.hpp"

namespace opencnc::hal {

// HAL's pin types (hal.h: hal_bit_t, hal_float_t, hal_s32_t, hal_u32_t); the component checks them.
using Bit = volatile bool;
using Float = volatile double;
using S32 = volatile std::int32_t;

/// One joint's pins (names: opencnc.joint.N.<name>). Null pointers are not allowed: every pin
/// exists; the profile says which ones are wired (the capabilities).
struct JointPins {
  Float* pos_cmd = nullptr;     ///< out: position command, joint units (servo and stepper joints)
  Float* vel_cmd = nullptr;     ///< out: velocity feed-forward, units/s
  S32* step_cmd = nullptr;      ///< out: stepper joints: absolute step count (low 32 bits)
  Float* pos_fb = nullptr;      ///< in: feedback position, joint units
  Bit* enable = nullptr;        ///< out: amplifier / step generator enable
  Bit* amp_fault = nullptr;     ///< in: the drive reports a fault
  Bit* home_sw = nullptr;       ///< in: home switch
  Bit* limit_min = nullptr;     ///< in: negative-end limit switch
  Bit* limit_max = nullptr;     ///< in: positive-end limit switch
  Bit* index_enable = nullptr;  ///< io: armed by us, cleared by the encoder at the index mark
  Float* effort = nullptr;      ///< in: the drive's force N or torque N·m (read when effort_wired)
};

/// The machine-wide pins (opencnc.<name>).
struct MachinePins {
  std::array<JointPins, machine::kMaxJoints> joints{};
  Bit* estop_in = nullptr;             ///< in: the external e-stop chain is closed (true = may run)
  Bit* estop_out = nullptr;            ///< out: the controller's contact in the chain (true = release)
  Bit* power_fail = nullptr;           ///< in: mains lost (true = lost)
  Bit* probe_in = nullptr;             ///< in: probe contact
  Float* spindle_speed_out = nullptr;  ///< out: commanded rpm, signed (+ = clockwise)
  Bit *spindle_on = nullptr, *spindle_forward = nullptr, *spindle_reverse = nullptr;  ///< out
  Bit* spindle_orient = nullptr;                          ///< out: M19 orient request
  Float* spindle_orient_angle = nullptr;                  ///< out: degrees
  Float* spindle_speed_in = nullptr;                      ///< in: measured rpm, signed
  Float* spindle_revs = nullptr;                          ///< in: spindle encoder position, revolutions
  Bit* spindle_at_speed = nullptr;                        ///< in
  Bit* spindle_orient_done = nullptr;                     ///< in
  Bit* spindle_fault = nullptr;                           ///< in
  Float* spindle_torque = nullptr;                        ///< in: N·m, signed (read when effort_wired)
  Bit *flood = nullptr, *mist = nullptr;                  ///< out: coolant
  S32* tool_prepare_number = nullptr;                     ///< out
  Bit *tool_prepare = nullptr, *tool_change = nullptr;    ///< out
  Bit *tool_prepared = nullptr, *tool_changed = nullptr;  ///< in
  S32* handwheel_counts = nullptr;                        ///< in: MPG counts (encoder.counts)
  std::array<Bit*, machine::kDigitalChannels> digital_in{}, digital_out{};  ///< first din/dout exist
  std::array<Float*, machine::kAnalogChannels> analog_in{}, analog_out{};   ///< first ain/aout exist
  int digital_inputs = 0, digital_outputs = 0, analog_inputs = 0, analog_outputs = 0;
  int joint_count = 0;  ///< joints with pins (the component's `joints=` parameter)
  /// The drives' efforts are netted to `joint.N.effort` and `spindle.torque` (the component's
  /// `effort=1`): an unconnected HAL pin reads 0, which must not pass for a measured load.
  bool effort_wired = false;
};

/// MachineIO over the pins. The capabilities are the profile's, handed over with the controller's
/// set-up and clipped to the pins that exist.
class HalMachine final : public control::ConfigurableMachine {
 public:
  /// Setup thread. `pins` (in HAL's shared memory) must outlive the backend.
  explicit HalMachine(const MachinePins& pins) noexcept : pins_(&pins) {}

  /// Setup thread, or the servo thread between periods.
  machine::MachineCapabilities capabilities() const noexcept override { return caps_; }
  /// Servo thread; real-time safe.
  void set_capabilities(const machine::MachineCapabilities& caps) noexcept override;
  /// Servo thread; real-time safe.
  void read(machine::MachineInputs& in) noexcept override;
  /// Servo thread; real-time safe.
  void write(const machine::MachineOutputs& out) noexcept override;
  /// Sets the period the index extrapolation uses (the HAL thread's), ns. Servo thread.
  void set_period_ns(std::int64_t period_ns) noexcept { period_s_ = static_cast<double>(period_ns) * 1e-9; }

 private:
  void read_joint(int j, machine::JointInputs& in) noexcept;
  void read_spindle(machine::SpindleInputs& in) noexcept;

  const MachinePins* pins_;
  machine::MachineCapabilities caps_{};
  std::uint64_t cycle_ = 0;
  double period_s_ = 0.001;
  /// Index handling: the encoder zeroes its count at the mark; we keep the position continuous.
  std::array<double, machine::kMaxJoints> fb_offset_{}, last_position_{}, last_velocity_{};
  std::array<std::uint32_t, machine::kMaxJoints> index_count_{};
  std::array<double, machine::kMaxJoints> index_position_{};
  std::array<bool, machine::kMaxJoints> index_armed_{};
};

}  // namespace opencnc::hal
