// SPDX-License-Identifier: GPL-3.0-or-later
// Program tails (restart from a position) and canon actions → machine actions.
#include "opencnc/controller/program_tools.hpp"

#include "opencnc/motion/coupling.hpp"

#include <unordered_map>

namespace opencnc::control {

namespace {

using canon::ActionKind;

/// Actions that set how later moves are planned (the planner reads them as it goes).
bool is_setting(ActionKind k) {
  switch (k) {
    case ActionKind::MotionControl:
    case ActionKind::NaiveCamTolerance:
    case ActionKind::FeedOverrideEnable:
    case ActionKind::FeedOverrideDisable:
    case ActionKind::FeedHoldEnable:
    case ActionKind::FeedHoldDisable:
    case ActionKind::SpeedFeedSyncStart:
    case ActionKind::SpeedFeedSyncStop:
      return true;
    default:
      return false;
  }
}

/// Copies an action's text and pose into `to` (new indices).
canon::Action copy_action(const canon::Program& from, canon::Program& to, canon::Action a,
                          std::unordered_map<std::uint32_t, std::uint32_t>& texts) {
  const bool has_text =
      a.kind == ActionKind::Message || a.kind == ActionKind::Comment || a.kind == ActionKind::WaitInput;
  if (has_text) {
    auto it = texts.find(a.text);
    if (it == texts.end()) it = texts.emplace(a.text, to.add_text(from.text(a.text))).first;
    a.text = it->second;
  }
  const bool has_pose = a.kind == ActionKind::ToolLengthOffset || a.kind == ActionKind::WorkOffset ||
                        a.kind == ActionKind::G92Offset;
  if (has_pose || a.kind == ActionKind::AxisCoupling) a.pose = to.add_action_pose(from.action_pose(a.pose));
  if (a.origin != 0) a.origin = 1 + to.add_action_pose(from.action_pose(a.origin - 1));
  return a;
}

}  // namespace

std::shared_ptr<canon::Program> program_tail(const canon::Program& program, canon::SegmentId from,
                                             const Pose& start) {
  auto out = std::make_shared<canon::Program>(program.axes());
  out->set_sources(program.sources_ptr());
  out->set_start(start);
  std::unordered_map<std::uint32_t, std::uint32_t> texts;
  for (std::size_t i = 0; i < program.action_count(); ++i) {
    canon::Action a = program.action(i);
    if (a.before_move < from && !is_setting(a.kind)) continue;
    a.before_move = a.before_move < from ? 0 : static_cast<std::uint32_t>(a.before_move - from);
    out->add_action(copy_action(program, *out, a, texts));
  }
  double last_feed = -1;
  std::uint32_t feed_index = 0;
  for (canon::SegmentId id = from; id < program.size(); ++id) {
    canon::Move m = program.move(id);
    const double f = program.feed(id);
    if (f != last_feed || out->size() == 0) {
      feed_index = out->add_feed(f);
      last_feed = f;
    }
    if (m.kind == canon::MoveKind::Arc) {
      canon::ArcGeometry g = program.arc(id);
      g.feed = feed_index;
      m.param = out->add_arc(g);
    } else {
      m.param = feed_index;
    }
    out->append(m, program.end(id));
  }
  return out;
}

std::optional<MachineAction> machine_action(const canon::Program& program, std::uint32_t index,
                                            const motion::CouplingConfig* coupling) {
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
      if (a.origin != 0 && coupling != nullptr && coupling->master_axis >= 0 && coupling->slave_axis >= 0) {
        const Pose& origin = program.action_pose(a.origin - 1);
        m.has_origin = true;
        m.master_origin = origin[coupling->master_axis];
        m.slave_origin = origin[coupling->slave_axis];
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
