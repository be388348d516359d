// SPDX-License-Identifier: GPL-3.0-or-later
// Interlock rules — what a machine's PLC did (spindle and coolant stops, blocked starts, holds,
// e-stop, lamps), declared in the machine profile and compiled into fixed-size plain data that
// the servo tick evaluates every period. The rule language is in docs/machine.md.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

namespace opencnc::machine {

inline constexpr int kMaxInterlockRules = 32;
/// Tokens of one compiled condition (signals and operators in postfix order).
inline constexpr int kMaxRuleTokens = 32;

/// What a signal of a condition reads (each is true or false every period).
enum class SignalKind : std::uint8_t {
  DigitalInput,    ///< `index` = channel (a named input of the profile)
  DigitalOutput,   ///< `index` = channel (a named output: what the controller writes)
  EStop,           ///< the e-stop chain is open or the machine is e-stopped
  MachineOn,       ///< the drives are enabled
  SpindleOn,       ///< the spindle is commanded to turn
  SpindleAtSpeed,  ///< the spindle drive reports its speed
  Coolant,         ///< flood or mist is on
  TableStill,      ///< no driven joint moved in the last two periods
  ProgramRunning,  ///< an Auto or MDI run is active
  AxisHomed,       ///< `index` = joint
  AxisMoving,      ///< `index` = joint: its command changed in the last period
  AxisLimitMin,    ///< `index` = joint: its negative limit switch
  AxisLimitMax,    ///< `index` = joint
  AxisHomeSwitch,  ///< `index` = joint
};

enum class TokenOp : std::uint8_t { Signal, Not, And, Or };

struct RuleToken {
  TokenOp op = TokenOp::Signal;
  SignalKind signal = SignalKind::EStop;
  std::uint8_t index = 0;
};

/// What a rule does (docs/machine.md, "Interlock rules").
enum class InterlockAction : std::uint8_t {
  StopSpindle,   ///< when the condition becomes true: the spindle stops (as M5)
  StopCoolant,   ///< when it becomes true: flood and mist off
  HoldMotion,    ///< when it becomes true: feed hold of a run, jogs stop
  BlockSpindle,  ///< while true: a spindle start is refused (a program's M3/M4 waits)
  BlockMotion,   ///< while true: no motion may start (jog, home, run, resume)
  EStop,         ///< while true: e-stopped, and reset is refused
  SetOutput,     ///< the digital output `output` follows the condition
};

/// One compiled rule: `action` applies according to the postfix condition `tokens`.
struct InterlockRule {
  InterlockAction action = InterlockAction::StopSpindle;
  std::uint8_t output = 0;  ///< SetOutput: the channel
  std::uint8_t token_count = 0;
  std::array<RuleToken, kMaxRuleTokens> tokens{};
  std::uint16_t line = 0;  ///< where the rule is in the profile (for messages)
};

struct InterlockRules {
  int count = 0;
  std::array<InterlockRule, kMaxInterlockRules> rules{};
};

static_assert(std::is_trivially_copyable_v<InterlockRules>);

}  // namespace opencnc::machine
