// SPDX-License-Identifier: GPL-3.0-or-later
// OffsetTrack: offset actions of a job's stream folded into the offsets of each move.
#include "offset_track.hpp"

namespace opencnc::controller::detail {

void OffsetTrack::scan(const canon::Program& p) {
  if (next_action_ < p.first_held_action()) next_action_ = p.first_held_action();
  for (; next_action_ < p.action_count(); ++next_action_) {
    const canon::Action& a = p.action(next_action_);
    switch (a.kind) {
      case canon::ActionKind::WorkOffset:
        latest_.system = static_cast<std::uint8_t>(a.index);
        latest_.g5x = p.action_pose(a.pose);
        break;
      case canon::ActionKind::G92Offset:
        latest_.g92 = p.action_pose(a.pose);
        break;
      case canon::ActionKind::ToolLengthOffset:
        latest_.tool = p.action_pose(a.pose);
        break;
      case canon::ActionKind::XyRotation:
        latest_.xy_rotation_deg = a.value;
        break;
      default:
        continue;
    }
    // Several changes before the same move are one change.
    if (!changes_.empty() && changes_.back().first == a.before_move)
      changes_.back().second = latest_;
    else
      changes_.emplace_back(a.before_move, latest_);
  }
}

const WorkOffsets& OffsetTrack::at(std::size_t move) {
  while (!changes_.empty() && changes_.front().first <= move) {
    base_ = changes_.front().second;
    changes_.pop_front();
  }
  return base_;
}

void OffsetTrack::restart(std::size_t from) {
  // The changes before `from` are kept with the move they come before (at() folds them in
  // ascending order, and `from` maps to the new leg's move 0).
  while (!changes_.empty() && changes_.back().first > from) changes_.pop_back();
  at(from);
  latest_ = base_;
  changes_.clear();
  next_action_ = 0;
}

}  // namespace opencnc::controller::detail
