// SPDX-License-Identifier: GPL-3.0-or-later
// MachineIO: the one boundary between the servo tick and a machine (simulated or real).
//
// Everything that crosses it is plain fixed-size data (no pointers, no heap, trivially
// copyable), so the two images below can later live in shared memory or be copied to and from
// LinuxCNC HAL pins. A servo period is: read(inputs) → control → write(outputs). The per-field
// table (unit, direction, required/optional, who reads it when) is in docs/machine.md.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

namespace opencnc::machine {

inline constexpr int kMaxJoints = 9;
/// Generic digital channels (M62–M65 outputs, M66 inputs): one bit each in a 64-bit word.
inline constexpr int kDigitalChannels = 64;
/// Generic analog channels (M67/M68 outputs, M66 E inputs).
inline constexpr int kAnalogChannels = 16;

/// How a joint is driven.
enum class JointDrive : std::uint8_t {
  Servo,    ///< position (+ velocity feed-forward) command to a drive; encoder feedback
  Stepper,  ///< absolute step count to a step generator; feedback = steps emitted
  Manual,   ///< moved by hand (a hand wheel): never commanded; feedback = its scale
};

enum class SpindleDirection : std::uint8_t { Stopped, Clockwise, Counterclockwise };

// ---------------------------------------------------------------------------------------
// Outputs: written by the servo tick once per period, held by the machine until the next.
// ---------------------------------------------------------------------------------------

/// Commands to one joint. Units are the joint's: mm (linear) or degrees (rotary).
struct JointOutputs {
  /// Servo: position the joint shall be at now (after axis coupling and compensation).
  double position = 0;
  /// Servo: velocity feed-forward, units/s. The drive extrapolates the position reference
  /// with it over the period; 0 gives a staircase reference and a larger following error.
  double velocity_ff = 0;
  /// Stepper: absolute commanded motor step count; the step generator spreads the difference
  /// to the previous period's count evenly over this period.
  std::int64_t step_position = 0;
  /// Amplifier (or step generator) enable. While false the motor produces no force.
  bool enable = false;
};

struct SpindleOutputs {
  double speed_rpm = 0;  ///< commanded speed magnitude, ≥ 0
  SpindleDirection direction = SpindleDirection::Stopped;
  /// M19: stop and hold the spindle at `orient_angle_deg` (0 = index mark, + = clockwise)
  /// while true; overrides speed and direction. Optional (capability `spindle_orient`).
  bool orient = false;
  double orient_angle_deg = 0;
};

/// EDM: the pulse generator's settings (the active machining condition, docs/edm.md).
struct GeneratorOutputs {
  double on_time_us = 0;      ///< pulse on-time
  double off_time_us = 0;     ///< pause between pulses
  double peak_current_a = 0;  ///< discharge current
  double voltage_v = 0;       ///< open-circuit voltage
  std::int8_t polarity = 1;   ///< +1: electrode positive
  std::int32_t condition = 0;  ///< the condition's number (a generator with its own tables selects by it)
};

/// Process outputs: coolant, and the process-specific ones of the machine types we run.
struct ProcessOutputs {
  bool flood = false;         ///< M8
  bool mist = false;          ///< M7
  bool torch_on = false;      ///< flame/plasma cutter: ignite and hold the torch
  bool generator_on = false;  ///< EDM: pulse generator on
  GeneratorOutputs generator{};  ///< EDM: its settings while on
};

/// Tool changer handshake (both sides level-triggered: a request stays up until acknowledged
/// and the tick takes it down; the acknowledgement follows it down).
struct ToolChangerOutputs {
  std::int32_t prepare_tool = 0;  ///< pocket/tool number to bring to the change position
  bool prepare = false;           ///< T word: request prepare of `prepare_tool`
  bool change = false;            ///< M6: request the change itself
};

/// Everything the servo tick writes in one period.
struct MachineOutputs {
  std::array<JointOutputs, kMaxJoints> joints{};
  /// The controller's contact in the e-stop chain: true lets the machine have power.
  bool estop_release = false;
  SpindleOutputs spindle{};
  ProcessOutputs process{};
  ToolChangerOutputs tool{};
  std::uint64_t digital_out = 0;                     ///< bit i = generic digital output i (M62–M65)
  std::array<double, kAnalogChannels> analog_out{};  ///< generic analog outputs (M67/M68)
};

// ---------------------------------------------------------------------------------------
// Inputs: sampled by the machine at the end of a period, read by the next servo tick.
// Switch bits are "active" = true whatever the contact wiring; backends invert NC contacts.
// ---------------------------------------------------------------------------------------

struct JointInputs {
  /// Feedback position, units (encoder counts / counts per unit, so quantised). Stepper:
  /// steps emitted / steps per unit.
  double position = 0;
  double velocity = 0;  ///< feedback velocity, units/s (as the drive estimates it)
  double effort = 0;    ///< drive force N (linear) or torque N·m (rotary); optional
  /// Encoder index (reference) marks passed since start; wraps. Compare with the previous
  /// period's value: a change means `index_position` holds a new latch. Optional.
  std::uint32_t index_count = 0;
  double index_position = 0;  ///< feedback position of the last index mark passed
  bool amp_fault = false;     ///< drive reports a fault (overcurrent, undervoltage, …)
  bool limit_neg = false;     ///< negative-end limit switch active (optional)
  bool limit_pos = false;     ///< positive-end limit switch active (optional)
  bool home = false;          ///< home (proximity) switch active (optional)
  bool decel = false;         ///< deceleration dog switch active (optional)
  /// Analog level of the home proximity sensor, 0 (nothing sensed) … 1 (fully covered), sampled
  /// with `home`; homing interpolates its threshold crossings between periods. Optional
  /// (capability `home_level`).
  double home_level = 0;
  bool stall = false;  ///< the stepper drive's stall detector reports lost steps (optional)
};

struct SpindleInputs {
  /// Spindle encoder position in revolutions, continuous (integer part = turns since start,
  /// + = clockwise), quantised to the encoder's counts per revolution. Optional (encoder).
  double position_rev = 0;
  double speed_rpm = 0;           ///< measured speed, signed (+ = clockwise)
  std::uint32_t index_count = 0;  ///< index pulses seen since start; wraps (encoder)
  double index_position_rev = 0;  ///< position_rev of the last index pulse (encoder)
  bool at_speed = false;          ///< drive reports speed within tolerance of command
  bool orient_done = false;       ///< orient requested and reached (capability)
  bool fault = false;             ///< spindle drive fault
  /// The drive's torque at the spindle, N·m, signed like the speed (+ drives clockwise); optional
  /// (capability `spindle_torque`). What the spindle's LOAD is measured from.
  double torque_nm = 0;
};

/// Power supply monitoring; optional (capability `power_monitor`).
struct PowerInputs {
  bool mains_ok = true;         ///< mains present
  bool ups_on_battery = false;  ///< the UPS feeds the machine from its battery
  double dc_link_v = 0;         ///< drives' DC bus voltage, V
};

/// EDM: what the generator's pulse discriminator saw in the last period.
enum class GapState : std::uint8_t {
  Open,    ///< no discharge: the gap is too wide (voltage at the open-circuit value)
  Normal,  ///< discharges after an ignition delay
  Arc,     ///< discharges without ignition delay at one spot (debris): damaging
  Short,   ///< electrode and work touch (or debris bridges them): no voltage
};

struct ProcessInputs {
  bool arc_ok = false;       ///< torch arc/flame established (optional)
  double gap_voltage_v = 0;  ///< EDM mean gap voltage over the period, V (optional: generator)
  GapState gap_state = GapState::Open;  ///< EDM discharge state (optional: generator)
};

struct ToolChangerInputs {
  bool prepared = false;  ///< acknowledges `prepare`
  bool changed = false;   ///< acknowledges `change`
};

/// Everything the servo tick reads in one period.
struct MachineInputs {
  std::uint64_t cycle = 0;  ///< periods the machine has run; a gap means a missed period
  std::array<JointInputs, kMaxJoints> joints{};
  /// The external e-stop chain is closed (no button pressed, no external fault). It does
  /// not include the controller's own `estop_release`.
  bool estop_ok = false;
  PowerInputs power{};
  SpindleInputs spindle{};
  bool probe = false;  ///< probe input active (optional)
  /// Optional: every joint's position where the probe input last changed state, captured at the
  /// edge (encoder latches of Mesa cards, EtherCAT touch probe), and a count of the edges so
  /// far. A backend without a latch leaves the count at 0; the servo then estimates the edge
  /// from its own samples.
  std::uint32_t probe_edges = 0;
  std::array<double, kMaxJoints> probe_latch{};
  ProcessInputs process{};
  ToolChangerInputs tool{};
  std::uint64_t digital_in = 0;                     ///< bit i = generic digital input i (M66 P)
  std::array<double, kAnalogChannels> analog_in{};  ///< generic analog inputs (M66 E)
  /// Manual pulse generator (handwheel): counts turned since start, + = clockwise; wraps.
  /// Optional (capability `handwheel`).
  std::int32_t handwheel_count = 0;
};

// ---------------------------------------------------------------------------------------
// Capabilities: which optional inputs and outputs a backend actually has wired. Fields a
// capability does not cover must be ignored by the controller (they stay at their defaults).
// ---------------------------------------------------------------------------------------

/// Bit per joint switch input.
enum SwitchBits : std::uint8_t {
  kSwitchLimitNeg = 1u << 0,
  kSwitchLimitPos = 1u << 1,
  kSwitchHome = 1u << 2,
  kSwitchDecel = 1u << 3,
};

struct JointCapabilities {
  JointDrive drive = JointDrive::Servo;
  std::uint8_t switches = 0;  ///< SwitchBits present
  bool index = false;         ///< index_count/index_position are valid
  bool effort = false;        ///< effort is valid
  bool home_level = false;    ///< home_level is valid (an analog home proximity sensor)
  bool stall_detect = false;  ///< stall is valid (a stepper drive with a stall detector)
};

struct MachineCapabilities {
  int joint_count = 0;  ///< joints 0 … joint_count-1 are connected
  std::array<JointCapabilities, kMaxJoints> joints{};
  bool spindle = false;          ///< spindle outputs drive something
  bool spindle_encoder = false;  ///< spindle position/index inputs are valid
  bool spindle_orient = false;
  bool spindle_torque = false;  ///< SpindleInputs::torque_nm is valid
  bool power_monitor = false;  ///< PowerInputs are valid
  bool ups = false;            ///< ups_on_battery is valid
  bool probe = false;
  bool tool_changer = false;
  bool torch = false;                           ///< torch_on / arc_ok
  bool generator = false;                       ///< generator_on / gap_voltage_v
  int digital_inputs = 0, digital_outputs = 0;  ///< generic channels 0 … n-1 exist
  int analog_inputs = 0, analog_outputs = 0;
  bool handwheel = false;  ///< handwheel_count is valid
};

// Images must stay plain data: they will be copied into shared memory and HAL pins.
static_assert(std::is_trivially_copyable_v<MachineOutputs> && std::is_standard_layout_v<MachineOutputs>);
static_assert(std::is_trivially_copyable_v<MachineInputs> && std::is_standard_layout_v<MachineInputs>);
static_assert(std::is_trivially_copyable_v<MachineCapabilities>);

/// A machine backend (simulated machine, LinuxCNC HAL pins, …). The servo thread calls
/// read() then write() exactly once per servo period, in that order; nothing else touches
/// the backend while it runs.
class MachineIO {
 public:
  virtual ~MachineIO() = default;

  /// What this backend has wired. Required. Non-real-time; called once before the first
  /// read(), from the thread that sets the controller up. Constant for the backend's life.
  virtual MachineCapabilities capabilities() const noexcept = 0;

  /// Copies the inputs sampled at the end of the last period into `in`. Required. Servo
  /// thread; real-time safe; idempotent within a period.
  virtual void read(MachineInputs& in) noexcept = 0;

  /// Hands the outputs of this period to the machine; they hold until the next write().
  /// Required. Servo thread; real-time safe. A simulated backend advances its virtual time
  /// by one servo period here; a real one only latches the values.
  virtual void write(const MachineOutputs& out) noexcept = 0;
};

}  // namespace opencnc::machine
