// SPDX-License-Identifier: GPL-3.0-or-later
// The controller's vocabulary as plain data: modes, states, commands, refusals, faults, and the
// events the servo reports. Everything here can cross the real-time boundary (shared memory).
#pragma once

#include <cstdint>
#include <type_traits>

namespace opencnc::control {

/// Operating mode (docs/controller.md).
enum class Mode : std::uint8_t {
  Manual,  ///< jog, home, manual spindle and coolant
  Mdi,     ///< one typed line at a time
  Auto,    ///< a program file
};

/// Controller state. Every transition is listed (and tested) in docs/controller.md.
enum class State : std::uint8_t {
  EStopped,  ///< e-stop: no power to the drives until reset with the e-stop chain closed
  Off,       ///< machine off: reset, drives disabled; machine-on enables them
  Idle,      ///< on, nothing moving
  Running,   ///< a jog, homing, MDI line or program is executing (including dwells and waits)
  Held,      ///< feed hold: stopping or stopped on the path; resume continues
  Stopped,   ///< program stop (M0), optional stop (M1) or single-block stop; cycle start continues
  Faulted,   ///< a fault stopped the machine (see Fault); reset clears it once the cause is gone
};

/// What Running, Held and Stopped refer to.
enum class Activity : std::uint8_t { None, Jog, Homing, Program };

/// What a running program waits for, if anything.
enum class Wait : std::uint8_t {
  None,
  Dwell,             ///< G4
  Spindle,           ///< the spindle reaching its speed (after M3/M4)
  ToolChanger,       ///< M6 with a tool changer: its acknowledgement
  ManualToolChange,  ///< M6 without one: the operator's tool-changed command
  Input,             ///< M66
  Orient,            ///< M19
  Probe,             ///< the end of a probe move
  Starved,           ///< the planner has not delivered the next blocks yet
  HandAxis,          ///< the operator bringing a hand-fed axis to a position (status: hand_wait)
  Interlock,         ///< an interlock rule holds back the next step (status: interlock_rule)
};

/// Why the state is Stopped.
enum class StopReason : std::uint8_t { None, ProgramStop, OptionalStop, SingleBlock };

/// A coolant output (the Coolant command's `coolant`).
enum class Coolant : std::uint8_t { Flood, Mist };

/// What the servo tick executes. Requests that only the controller handles (opening programs,
/// MDI lines, …) are the controller layer's (controller/request.hpp) and never reach the tick.
enum class CommandKind : std::uint8_t {
  EStop,               ///< stop everything now, drives off
  Reset,               ///< leave EStopped or Faulted (to Off) once the cause is gone
  MachineOn,           ///< Off → Idle: drives enabled, commanded position = actual
  MachineOff,          ///< → Off: drives disabled (a running motion stops at once)
  SetMode,             ///< `mode`; only while nothing runs
  JogContinuous,       ///< `axis`, `value` = signed speed (units/s); stops at the soft limit
  JogIncrement,        ///< `axis`, `value` = signed distance, `value2` = speed (units/s)
  JogStop,             ///< `axis` (−1 = every axis): decelerate and stop
  Home,                ///< `axis` (−1 = all, in their sequences)
  StartRun,            ///< the controller's own: run the blocks queued from `first_block` on;
                       ///< `flag`: it resumes an interrupted program (a cut goes on there)
  CycleStart,          ///< continue after M0/M1/single block or feed hold (starting a program is
                       ///< the controller's: it plans, then sends StartRun)
  FeedHold,            ///< stop on the path; resume continues
  Resume,              ///< continue after feed hold (or a program stop)
  Abort,               ///< controlled stop of whatever moves, then Idle; the program is dropped
  SetSingleBlock,      ///< `flag`
  SetOptionalStop,     ///< `flag`: M1 stops while on
  SetFeedOverride,     ///< `value` 0 … 2 (0–200 %)
  SetRapidOverride,    ///< `value` 0 … 1
  SetSpindleOverride,  ///< `value` 0 … 2
  ToolChanged,         ///< the operator has changed the tool by hand (manual M6)
  SpindleOn,           ///< manual: `value` rpm, `flag` true = clockwise
  SpindleOff,          ///< manual
  Coolant,             ///< manual: `coolant` on (`flag`) or off
  SetHandwheel,        ///< `axis` the handwheel moves (−1 = none), `value` = units per count
  StageJointLimits,    ///< `axis` = joint: `limits` wait for ApplyJointLimits (no effect yet)
  ApplyJointLimits,  ///< the staged joints' limits (and tables) take effect at once, only while nothing moves
  /// `axis` = joint, `table_buffer` = 0/1: that joint's buffer of ServoChannels::pitch_tables is
  /// its new pitch-error table from the next ApplyJointLimits on (no effect yet)
  StagePitchTable,
  /// ServoChannels::edm_conditions are the EDM's machining conditions from the next
  /// ApplyJointLimits on (checked there; no effect yet)
  StageEdmConditions,
  /// `axis`, `value` = +1 / −1: jog to that limit switch, latch it slowly, back off onto its free
  /// side (LimitSeek); Manual mode, idle, the axis with that switch and seek keys
  SeekLimit,
  /// Oxy-fuel: the operator's start of the cut while the torch preheats (cutting oxygen on,
  /// pierce); refused (NotApplicable) unless a preheat is under way
  StartCut,
};

/// Why a command was refused. Each has a stable code (refusal_code()).
enum class Refusal : std::uint8_t {
  None,
  EStopActive,    ///< control.estop: e-stopped; reset first
  EStopInput,     ///< control.estop-input: the e-stop chain is still open
  MachineOff,     ///< control.machine-off: needs the machine on
  Faulted,        ///< control.faulted: reset the fault first
  FaultPersists,  ///< control.fault-persists: the cause of the fault is still there
  WrongMode,      ///< control.wrong-mode: not in the mode this command belongs to
  Busy,           ///< control.busy: something is running (or held) that this would disturb
  NotHomed,       ///< control.not-homed: the machine must be homed first
  NotApplicable,  ///< control.not-applicable: nothing to do in this state
  BadValue,       ///< control.bad-value: an argument out of range or an unknown axis
  LimitSwitch,    ///< control.limit-switch: a jog toward an active limit switch
  NoProgram,      ///< control.no-program: cycle start in Auto without an open program
  ProgramError,   ///< control.program: the program or MDI line was rejected (see diagnostics)
  SoftLimit,      ///< control.soft-limit: the program would cross a soft limit (preflight)
  StartMismatch,  ///< control.start-mismatch: the queued motion does not start where the machine is
  Interlock,      ///< control.interlock: an interlock rule of the profile forbids it now
  HandAxis,       ///< control.hand-axis: the axis is moved by hand, or is not where the program needs it
  FeatureCheck,   ///< control.feature-check: a feature's check before the start failed (the message says why)
  NoLimitSwitch,  ///< control.no-limit-switch: the axis has no limit switch that way to seek (or no seek
                  ///< keys)
  /// control.superseded: an e-stop, machine off, abort or feed hold was sent after this request and
  /// acted first; what this one would have started is dropped (send it again to mean it)
  Superseded,
};

/// Stable problem code of a refusal ("control.busy", ...). Any thread; real-time safe.
const char* refusal_code(Refusal r) noexcept;

/// What stopped the machine.
enum class FaultKind : std::uint8_t {
  None,
  LimitSwitch,     ///< `axis`, `value` = position where it tripped
  AmpFault,        ///< `axis`
  FollowingError,  ///< `axis`, `value` = error, `limit` = the profile's maximum
  SoftLimit,       ///< `axis`, `value` = commanded position, `limit` = the soft limit (tick check)
  PowerLoss,       ///< mains lost or UPS on battery: `value` = DC link volts
  Homing,          ///< `axis`: a homing move ran into a limit or found no switch (`value` = where)
  Stall,           ///< `axis`: the stepper drive detected a stall (steps were lost; home again)
  ProcessAlarm,    ///< a `stop` alarm: `axis` = the alarm's index, `value` = the input, `limit` = the bound
  EdmShort,  ///< the EDM gap stayed shorted: `axis` = the condition, `value` = seconds, `limit` = its limit
  /// The EDM finishing cycle did not bring the orbit to its size in time: `axis` = the condition,
  /// `value` = the orbit's radius reached (mm), `limit` = the condition's finish_timeout_s
  EdmFinishTimeout,
  /// A seek of a homed axis went its soft limit + overtravel without the limit switch tripping:
  /// `axis`, `value` = where it stopped, `limit` = the soft limit (the axis must home again)
  SeekNoSwitch,
  /// A coupling code's master or slave (`axis`) did not stand within `limit` of its command in
  /// the profile's engage_timeout_s: `value` = its following error then (the run stopped)
  CouplingPosition,
};

/// Stable problem code of a fault ("control.fault.following-error", ...). Any thread.
const char* fault_code(FaultKind k) noexcept;

/// A fault with the axis and the values that explain it. Plain data.
struct Fault {
  FaultKind kind = FaultKind::None;
  std::int8_t axis = -1;  ///< Axis index (X = 0 …), −1 = none
  double value = 0;
  double limit = 0;
  std::uint64_t tick = 0;
};

/// A joint's limits as an admin changes them (the profile's editable keys, less the compensation's
/// reserve as servo_config() computes them), with its backlash and take-up limits. Plain data.
struct JointLimits {
  double max_velocity = 0;      ///< units/s
  double max_acceleration = 0;  ///< units/s²
  double min_limit = 0;         ///< soft limits, machine coordinates
  double max_limit = 0;
  double max_following_error = 1;  ///< units
  double home_final_velocity = 0;  ///< units/s (bounded by max_velocity)
  // The compensation's scalars (motion::JointCompensation; joints without compensation: 0).
  double backlash = 0;             ///< units
  double takeup_velocity = 0;      ///< units/s
  double takeup_acceleration = 0;  ///< units/s²
};

/// One operator (or controller) command. Plain data; which fields apply depends on `kind`.
struct Command {
  std::uint64_t id = 0;  ///< chosen by the sender; echoed in the ServoEvent that answers it
  CommandKind kind = CommandKind::Abort;
  Mode mode = Mode::Manual;
  std::int8_t axis = -1;  ///< Axis index (X = 0 …), −1 = all / none
  bool flag = false;
  Coolant coolant = Coolant::Flood;
  double value = 0;
  double value2 = 0;
  // StartRun: fences below which queued blocks and actions are stale, and the run's number.
  std::uint64_t first_block = 0;
  std::uint64_t first_action = 0;
  std::uint32_t run_id = 0;
  Mode run_mode = Mode::Auto;  ///< StartRun: Auto program or MDI line
  JointLimits limits{};        ///< StageJointLimits
  std::uint8_t table_buffer = 0;  ///< StagePitchTable: which of the joint's two buffers
  /// The order in which the controller sent it, over both of its lanes (ServoChannels::commands
  /// and ::urgent): the tick applies what it finds in both in this order. 0: unordered (a test).
  std::uint64_t seq = 0;
};

/// What a program's marker asks the machine to do (canon actions, in a form the tick can apply).
enum class ActionCode : std::uint8_t {
  SpindleSpeed,  ///< value = rpm
  SpindleCw,
  SpindleCcw,
  SpindleStop,
  SelectTool,     ///< index = tool: prepare it
  ChangeTool,     ///< M6: the selected tool into the spindle (index = its table index)
  SetToolNumber,  ///< index = tool (M61)
  FloodOn,
  FloodOff,
  MistOn,
  MistOff,
  SpindleOverrideEnable,
  SpindleOverrideDisable,
  DigitalOutput,  ///< index = channel, index2 = 1 on / 0 off (M62–M65)
  AnalogOutput,   ///< index = channel, value (M67/M68)
  WaitInput,      ///< index = channel, index2 = mode (L0–L4), value = timeout s, digital = flag
  SpindleOrient,  ///< value = degrees
  PalletShuttle,
  Message,       ///< the controller shows the text (action index)
  Ignore,        ///< nothing for the machine (probe on/off)
  SpindleMode,   ///< G96: value = highest rpm (D); 0 = G97, the speed is in rpm again
  SurfaceSpeed,  ///< G96 S: value = surface speed (mm/min), value2 = X of the spindle axis (mm)
  /// Wait until the operator has brought hand axis `index` to `value`: index2 = +1 a retract (at
  /// or above it), 0 a plunge (down to it); see HandWait in status.hpp.
  HandAxisWait,
  /// Couple the profile's slave axis to its master (coupling stage): index = motion::CouplingKind
  /// (0 = uncouple), index2 = table number (1-based), value = pitch (mm), value2 = pitch rate.
  AxisCoupling,
  /// A machine module's process code (canon::ProcessCode): index = M number, value = P, value2 = Q
  /// (the EDM codes M180/M181: servo_gap.cpp).
  ProcessCode,
};

/// The machine side of marker `action` (Program::actions() index) of the current run. The
/// controller pushes one for every action that becomes a marker, in order.
struct MachineAction {
  std::uint32_t action = 0;
  ActionCode code = ActionCode::Ignore;
  bool digital = true;
  std::int32_t index = 0;
  std::int32_t index2 = 0;
  double value = 0;
  double value2 = 0;  ///< SurfaceSpeed: X of the spindle axis, machine coordinates (mm); AxisCoupling: pitch rate
  /// AxisCoupling: the law's origin (master, slave; machine coordinates) when it is not where the
  /// path stands (a resumed program re-engaging the law of a code before its segment).
  bool has_origin = false;
  double master_origin = 0, slave_origin = 0;
};

/// How a run ended.
enum class RunEnd : std::uint8_t {
  Finished,      ///< program end reached
  Aborted,       ///< abort command: controlled stop, rest of the program dropped
  ProbeTripped,  ///< a probe move tripped: controlled stop; the controller continues from there
  Faulted,       ///< a fault stopped it (power loss: after a controlled stop)
  EStopped,
  MachineOff,
};

/// What the servo reports to the controller, in order.
enum class EventKind : std::uint8_t {
  Accepted,      ///< command `command_id` was taken
  Refused,       ///< command `command_id` was refused for `refusal`
  StateChanged,  ///< `state` is the new state
  Fault,         ///< `fault` stopped the machine
  RunEnded,      ///< run `run_id` ended (`run_end`)
  Message,       ///< the program passed a message action (`action`) of run `run_id`
  Homed,         ///< `axis` is homed
  ProbeTripped,  ///< the probe tripped during run `run_id` (position in the status)
  InputRead,     ///< M66 of run `run_id` read `value` (−1: timed out)
  /// Run `run_id` went on past a sync point: a Sync marker whose handshake is done, or a program
  /// stop (M0, M1) — `action` (traj::kNoAction for the end of a probe move that did not trip),
  /// `segment`; the controller's interpreter may read on from there.
  SyncPassed,
  Interlock,      ///< interlock rule `action` (its index) acted (`command`: what it did, see below)
  HandAxisMoved,  ///< hand axis `axis` left the position the run needs while it moved: feed hold
  /// The load guard acted (`action`: a control::LoadAction) at load `value` kN; run `run_id`.
  LoadGuard,
  /// Process alarm `action` (its index) tripped: `value` = the input, `axis` 0 below its low
  /// bound, 1 above its high one; the profile's reaction says what followed (a `stop` alarm's
  /// Fault event comes next).
  ProcessAlarm,
  ProcessAlarmCleared,  ///< process alarm `action` is back in range (`value`)
  /// EDM: backing off reached the end of the path memory while the gap servo still drove back;
  /// the electrode holds there (`action` = the condition, `value` = how far behind the head, mm).
  EdmRetractLimit,
  /// A seek of a limit switch ended: `axis`, `action` 1 = found (`value` = where the switch
  /// tripped, machine position; the rest position is in the status), 0 = stopped before it.
  LimitSeek,
  /// Plasma: the torch stage tells `action` (a control::TorchEvent) with `value`; run `run_id`.
  Torch,
};

struct ServoEvent {
  std::uint64_t tick = 0;
  EventKind kind = EventKind::Accepted;
  std::uint64_t command_id = 0;
  CommandKind command = CommandKind::Abort;
  Refusal refusal = Refusal::None;
  State state = State::Off;
  Fault fault{};
  std::uint32_t run_id = 0;
  RunEnd run_end = RunEnd::Finished;
  std::uint32_t action = 0;
  std::uint64_t segment = 0;  ///< RunEnded, ProbeTripped: segment at the commanded position
  std::int8_t axis = -1;
  double value = 0;
};

static_assert(std::is_trivially_copyable_v<JointLimits>);
static_assert(std::is_trivially_copyable_v<Command>);
static_assert(std::is_trivially_copyable_v<MachineAction>);
static_assert(std::is_trivially_copyable_v<ServoEvent>);

/// Names for logs and status lines. Any thread; real-time safe.
const char* to_string(Mode m) noexcept;
const char* to_string(State s) noexcept;
const char* to_string(CommandKind k) noexcept;

}  // namespace opencnc::control
