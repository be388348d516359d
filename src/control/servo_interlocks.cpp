// SPDX-License-Identifier: GPL-3.0-or-later
// Servo, interlocks: the profile's rules (what the machine's PLC did) evaluated every period after
// safety — edge-triggered stops and holds, blocked starts, e-stop, outputs that follow a condition.
#include "opencnc/control/servo.hpp"

namespace opencnc::control {

using machine::InterlockAction;
using machine::SignalKind;

bool Servo::signal(const machine::RuleToken& t) const noexcept {
  const auto j = static_cast<std::size_t>(t.index < machine::kMaxJoints ? t.index : 0);
  switch (t.signal) {
    case SignalKind::DigitalInput:
      return (in_.digital_in >> (t.index & 63)) & 1u;
    case SignalKind::DigitalOutput:
      return (out_.digital_out >> (t.index & 63)) & 1u;
    case SignalKind::EStop:
      return !in_.estop_ok || state_ == State::EStopped;
    case SignalKind::MachineOn:
      return drives_enabled_;
    case SignalKind::SpindleOn:
      return spindle_running_;
    case SignalKind::SpindleAtSpeed:
      return spindle_running_ && in_.spindle.at_speed;
    case SignalKind::Coolant:
      return flood_ || mist_;
    case SignalKind::TableStill:
      return !moved_last_ && activity_ != Activity::Jog && activity_ != Activity::Homing &&
             (activity_ != Activity::Program || tick_out_.path_velocity == 0);
    case SignalKind::ProgramRunning:
      return activity_ == Activity::Program;
    case SignalKind::AxisHomed:
      return homed_[j];
    case SignalKind::AxisMoving:
      return joint_velocity_[j] != 0;
    case SignalKind::AxisLimitMin:
      return in_.joints[j].limit_neg;
    case SignalKind::AxisLimitMax:
      return in_.joints[j].limit_pos;
    case SignalKind::AxisHomeSwitch:
      return in_.joints[j].home;
  }
  return false;
}

// The postfix condition on a stack of bits (at most kMaxRuleTokens deep: a bounded loop).
bool Servo::holds(const machine::InterlockRule& r) const noexcept {
  std::uint64_t stack = 0;
  int depth = 0;
  for (int k = 0; k < r.token_count && k < machine::kMaxRuleTokens; ++k) {
    const machine::RuleToken& t = r.tokens[static_cast<std::size_t>(k)];
    switch (t.op) {
      case machine::TokenOp::Signal:
        stack = (stack << 1) | (signal(t) ? 1u : 0u);
        ++depth;
        break;
      case machine::TokenOp::Not:
        stack ^= 1u;
        break;
      case machine::TokenOp::And:
      case machine::TokenOp::Or: {
        const std::uint64_t b = stack & 1u, a = (stack >> 1) & 1u;
        stack = (stack >> 2) << 1 | (t.op == machine::TokenOp::And ? (a & b) : (a | b));
        --depth;
        break;
      }
    }
  }
  return depth >= 1 && (stack & 1u);
}

void Servo::apply_interlocks() noexcept {
  const machine::InterlockRules& rules = config_.interlocks;
  if (rules.count == 0) return;
  motion_blocked_ = spindle_blocked_ = estop_rule_ = false;
  blocking_rule_ = -1;
  std::uint32_t now_true = 0;
  for (int i = 0; i < rules.count && i < machine::kMaxInterlockRules; ++i) {
    const machine::InterlockRule& r = rules.rules[static_cast<std::size_t>(i)];
    const bool now = holds(r);
    // Edges count from the first period on: a condition already true at power-up stops nothing.
    const bool before = rules_started_ ? ((rules_true_ >> i) & 1u) != 0 : now;
    if (now) now_true |= 1u << i;
    act_on_rule(i, r, now, before);
  }
  rules_true_ = now_true;
  rules_started_ = true;
}

void Servo::act_on_rule(int index, const machine::InterlockRule& r, bool now, bool before) noexcept {
  const bool rising = now && !before;
  switch (r.action) {
    case InterlockAction::StopSpindle:
      // A turning spindle: a start that a block holds back is a later wish (an M3 given with the
      // quill down starts once the quill is up, though the quill's arrival stops a turning one).
      if (rising && spindle_running_) {
        spindle_direction_ = machine::SpindleDirection::Stopped;
        spindle_changed_tick_ = tick_;
        orient_ = false;
        emit_interlock(index, CommandKind::SpindleOff);
      }
      break;
    case InterlockAction::StopCoolant:
      if (rising && (flood_ || mist_)) {
        flood_ = mist_ = false;
        emit_interlock(index, CommandKind::Coolant);
      }
      break;
    case InterlockAction::HoldMotion:
      if (!rising) break;
      if (activity_ == Activity::Program && !aborting_ && state_ == State::Running) {
        hold_ = true;
        set_state(State::Held);
        emit_interlock(index, CommandKind::FeedHold);
      } else if (activity_ == Activity::Jog || activity_ == Activity::Homing) {
        abort();  // jogs decelerate; homing is cancelled (the movers bring the joints to rest)
        emit_interlock(index, CommandKind::JogStop);
      }
      break;
    case InterlockAction::BlockSpindle:
      if (now && !spindle_blocked_) {
        spindle_blocked_ = true;
        if (blocking_rule_ < 0) blocking_rule_ = static_cast<std::int8_t>(index);
      }
      break;
    case InterlockAction::BlockMotion:
      motion_blocked_ = motion_blocked_ || now;
      break;
    case InterlockAction::EStop:
      estop_rule_ = estop_rule_ || now;
      if (now && state_ != State::EStopped) {
        enter_estop();
        emit_interlock(index, CommandKind::EStop);
      }
      break;
    case InterlockAction::SetOutput: {
      const std::uint64_t bit = std::uint64_t{1} << (r.output & 63);
      rule_outputs_mask_ |= bit;
      rule_outputs_ = now ? (rule_outputs_ | bit) : (rule_outputs_ & ~bit);
      break;
    }
  }
}

void Servo::emit_interlock(int index, CommandKind what) noexcept {
  ServoEvent e;
  e.kind = EventKind::Interlock;
  e.action = static_cast<std::uint32_t>(index);
  e.command = what;
  e.run_id = run_id_;
  emit(e);
}

bool Servo::spindle_may_start() const noexcept {
  return !spindle_blocked_;
}

}  // namespace opencnc::control
