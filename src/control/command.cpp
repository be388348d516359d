// SPDX-License-Identifier: GPL-3.0-or-later
// Names and stable problem codes of the controller's vocabulary.
#include "opencnc/control/command.hpp"

namespace opencnc::control {

const char* refusal_code(Refusal r) noexcept {
  switch (r) {
    case Refusal::None:
      return "";
    case Refusal::EStopActive:
      return "control.estop";
    case Refusal::EStopInput:
      return "control.estop-input";
    case Refusal::MachineOff:
      return "control.machine-off";
    case Refusal::Faulted:
      return "control.faulted";
    case Refusal::FaultPersists:
      return "control.fault-persists";
    case Refusal::WrongMode:
      return "control.wrong-mode";
    case Refusal::Busy:
      return "control.busy";
    case Refusal::NotHomed:
      return "control.not-homed";
    case Refusal::NotApplicable:
      return "control.not-applicable";
    case Refusal::BadValue:
      return "control.bad-value";
    case Refusal::LimitSwitch:
      return "control.limit-switch";
    case Refusal::NoProgram:
      return "control.no-program";
    case Refusal::ProgramError:
      return "control.program";
    case Refusal::SoftLimit:
      return "control.soft-limit";
    case Refusal::StartMismatch:
      return "control.start-mismatch";
    case Refusal::Interlock:
      return "control.interlock";
    case Refusal::HandAxis:
      return "control.hand-axis";
    case Refusal::FeatureCheck:
      return "control.feature-check";
    case Refusal::NoLimitSwitch:
      return "control.no-limit-switch";
    case Refusal::Superseded:
      return "control.superseded";
  }
  return "control.unknown";
}

const char* fault_code(FaultKind k) noexcept {
  switch (k) {
    case FaultKind::None:
      return "";
    case FaultKind::LimitSwitch:
      return "control.fault.limit-switch";
    case FaultKind::AmpFault:
      return "control.fault.amplifier";
    case FaultKind::FollowingError:
      return "control.fault.following-error";
    case FaultKind::SoftLimit:
      return "control.fault.soft-limit";
    case FaultKind::PowerLoss:
      return "control.fault.power-loss";
    case FaultKind::Homing:
      return "control.fault.homing";
    case FaultKind::Stall:
      return "control.fault.stall";
    case FaultKind::ProcessAlarm:
      return "control.fault.process-alarm";
    case FaultKind::EdmShort:
      return "control.fault.edm-short";
    case FaultKind::EdmFinishTimeout:
      return "control.fault.edm-finish-timeout";
    case FaultKind::SeekNoSwitch:
      return "control.fault.seek-limit";
    case FaultKind::CouplingPosition:
      return "control.fault.coupling-position";
  }
  return "control.fault.unknown";
}

const char* to_string(Mode m) noexcept {
  switch (m) {
    case Mode::Manual:
      return "manual";
    case Mode::Mdi:
      return "mdi";
    case Mode::Auto:
      return "auto";
  }
  return "?";
}

const char* to_string(State s) noexcept {
  switch (s) {
    case State::EStopped:
      return "e-stopped";
    case State::Off:
      return "off";
    case State::Idle:
      return "idle";
    case State::Running:
      return "running";
    case State::Held:
      return "held";
    case State::Stopped:
      return "stopped";
    case State::Faulted:
      return "faulted";
  }
  return "?";
}

const char* to_string(CommandKind k) noexcept {
  switch (k) {
    case CommandKind::EStop:
      return "e-stop";
    case CommandKind::Reset:
      return "reset";
    case CommandKind::MachineOn:
      return "machine-on";
    case CommandKind::MachineOff:
      return "machine-off";
    case CommandKind::SetMode:
      return "set-mode";
    case CommandKind::JogContinuous:
      return "jog";
    case CommandKind::JogIncrement:
      return "jog-increment";
    case CommandKind::JogStop:
      return "jog-stop";
    case CommandKind::Home:
      return "home";
    case CommandKind::StartRun:
      return "start-run";
    case CommandKind::CycleStart:
      return "cycle-start";
    case CommandKind::FeedHold:
      return "feed-hold";
    case CommandKind::Resume:
      return "resume";
    case CommandKind::Abort:
      return "abort";
    case CommandKind::SetSingleBlock:
      return "single-block";
    case CommandKind::SetOptionalStop:
      return "optional-stop";
    case CommandKind::SetFeedOverride:
      return "feed-override";
    case CommandKind::SetRapidOverride:
      return "rapid-override";
    case CommandKind::SetSpindleOverride:
      return "spindle-override";
    case CommandKind::ToolChanged:
      return "tool-changed";
    case CommandKind::SpindleOn:
      return "spindle-on";
    case CommandKind::SpindleOff:
      return "spindle-off";
    case CommandKind::Coolant:
      return "coolant";
    case CommandKind::SetHandwheel:
      return "handwheel";
    case CommandKind::StageJointLimits:
      return "stage-joint-limits";
    case CommandKind::ApplyJointLimits:
      return "apply-joint-limits";
    case CommandKind::StagePitchTable:
      return "stage-pitch-table";
    case CommandKind::StageEdmConditions:
      return "stage-edm-conditions";
    case CommandKind::SeekLimit:
      return "seek-limit";
    case CommandKind::StartCut:
      return "start-cut";
  }
  return "?";
}

}  // namespace opencnc::control
