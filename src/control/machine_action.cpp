// SPDX-License-Identifier: GPL-3.0-or-later
// A canonical program's actions as the machine actions the tick applies at its markers.
#include "opencnc/control/machine_action.hpp"

namespace opencnc::control {

std::optional<MachineAction> machine_action(const canon::Program& program, std::uint32_t index,
                                            const ServoConfig* servo) {
  using canon::ActionKind;
  const canon::Action& a = program.action(index);
  MachineAction m;
  m.action = index;
  m.index = a.index;
  m.index2 = a.index2;
  m.value = a.value;
  switch (a.kind) {
    case ActionKind::SpindleSpeed:
      m.code = ActionCode::SpindleSpeed;
      if (a.index2 == 1) {  // G96: a surface speed about the spindle axis at this X
        m.code = ActionCode::SurfaceSpeed;
        m.value2 = program.action_pose(a.pose)[Axis::X];
      }
      break;
    case ActionKind::SpindleMode:
      m.code = ActionCode::SpindleMode;
      break;
    case ActionKind::SpindleCw:
      m.code = ActionCode::SpindleCw;
      break;
    case ActionKind::SpindleCcw:
      m.code = ActionCode::SpindleCcw;
      break;
    case ActionKind::SpindleStop:
      m.code = ActionCode::SpindleStop;
      break;
    case ActionKind::SelectTool:
      m.code = ActionCode::SelectTool;
      break;
    case ActionKind::ChangeTool:
      m.code = ActionCode::ChangeTool;
      break;
    case ActionKind::ChangeToolNumber:
      m.code = ActionCode::SetToolNumber;
      break;
    case ActionKind::FloodOn:
      m.code = ActionCode::FloodOn;
      break;
    case ActionKind::FloodOff:
      m.code = ActionCode::FloodOff;
      break;
    case ActionKind::MistOn:
      m.code = ActionCode::MistOn;
      break;
    case ActionKind::MistOff:
      m.code = ActionCode::MistOff;
      break;
    case ActionKind::SpeedOverrideEnable:
      m.code = ActionCode::SpindleOverrideEnable;
      break;
    case ActionKind::SpeedOverrideDisable:
      m.code = ActionCode::SpindleOverrideDisable;
      break;
    case ActionKind::MotionOutputBit:
    case ActionKind::AuxOutputBit:
      m.code = ActionCode::DigitalOutput;
      break;
    case ActionKind::MotionOutputValue:
    case ActionKind::AuxOutputValue:
      m.code = ActionCode::AnalogOutput;
      break;
    case ActionKind::WaitInput:
      m.code = ActionCode::WaitInput;
      m.digital = program.text(a.text) != "analog";
      break;
    case ActionKind::SpindleOrient:
      m.code = ActionCode::SpindleOrient;
      break;
    case ActionKind::PalletShuttle:
      m.code = ActionCode::PalletShuttle;
      break;
    case ActionKind::Message:
      m.code = ActionCode::Message;
      break;
    case ActionKind::HandAxisWait:
      m.code = ActionCode::HandAxisWait;
      break;
    case ActionKind::AxisCoupling:
      m.code = ActionCode::AxisCoupling;
      m.value2 = program.action_pose(a.pose)[0];
      if (a.origin != 0 && servo != nullptr && servo->coupling.master_axis >= 0 &&
          servo->coupling.slave_axis >= 0) {
        const Pose& origin = program.action_pose(a.origin - 1);
        m.has_origin = true;
        m.master_origin = origin[servo->coupling.master_axis];
        m.slave_origin = origin[servo->coupling.slave_axis];
      }
      break;
    case ActionKind::ProcessCode:
      m.code = ActionCode::ProcessCode;
      m.value2 = program.action_pose(a.pose)[0];
      break;
    case ActionKind::ProbeOn:
    case ActionKind::ProbeOff:
      m.code = ActionCode::Ignore;
      break;
    default:
      return std::nullopt;  // no marker, or a marker the interpolator handles alone (dwell, stops)
  }
  return m;
}

}  // namespace opencnc::control
