// SPDX-License-Identifier: GPL-3.0-or-later
// Program tails: the rest of a program from one of its moves, started from another position.
#include "opencnc/canon/program_tail.hpp"

#include <unordered_map>

namespace opencnc::canon {

namespace {

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
Action copy_action(const Program& from, Program& to, Action a,
                   std::unordered_map<std::uint32_t, std::uint32_t>& texts) {
  const bool has_text =
      a.kind == ActionKind::Message || a.kind == ActionKind::Comment || a.kind == ActionKind::WaitInput;
  if (has_text) {
    auto it = texts.find(a.text);
    if (it == texts.end()) it = texts.emplace(a.text, to.add_text(from.text(a.text))).first;
    a.text = it->second;
  }
  if (has_pose(a)) a.pose = to.add_action_pose(from.action_pose(a.pose));
  if (a.origin != 0) a.origin = 1 + to.add_action_pose(from.action_pose(a.origin - 1));
  return a;
}

}  // namespace

std::shared_ptr<Program> program_tail(const Program& program, SegmentId from, const Pose& start) {
  auto out = std::make_shared<Program>(program.axes());
  out->set_sources(program.sources_ptr());
  out->set_start(start);
  std::unordered_map<std::uint32_t, std::uint32_t> texts;
  for (std::size_t i = 0; i < program.action_count(); ++i) {
    Action a = program.action(i);
    if (a.before_move < from && !is_setting(a.kind)) continue;
    a.before_move = a.before_move < from ? 0 : static_cast<std::uint32_t>(a.before_move - from);
    out->add_action(copy_action(program, *out, a, texts));
  }
  double last_feed = -1;
  std::uint32_t feed_index = 0;
  for (SegmentId id = from; id < program.size(); ++id) {
    Move m = program.move(id);
    const double f = program.feed(id);
    if (f != last_feed || out->size() == 0) {
      feed_index = out->add_feed(f);
      last_feed = f;
    }
    if (m.kind == MoveKind::Arc) {
      ArcGeometry g = program.arc(id);
      g.feed = feed_index;
      m.param = out->add_arc(g);
    } else {
      m.param = feed_index;
    }
    out->append(m, program.end(id));
  }
  return out;
}

}  // namespace opencnc::canon
