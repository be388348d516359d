// SPDX-License-Identifier: GPL-3.0-or-later
// Storage of the expanded program: 16-byte moves, strided poses, side tables.
#include "opencnc/canon/program.hpp"

#include <algorithm>

namespace opencnc::canon {

Program::Program(AxisMask axes) : axes_(axes), sources_(std::make_shared<SourceMap>()) {
  int slot = 0;
  for (int i = 0; i < kAxisCount; ++i) {
    if (!axes_.has(static_cast<Axis>(i))) continue;
    axis_slots_[i] = static_cast<std::uint8_t>(slot);
    slot_axes_[slot++] = static_cast<std::uint8_t>(i);
  }
  stride_ = slot;
}

Pose Program::end(SegmentId id) const noexcept {
  Pose p{};
  const std::size_t base = static_cast<std::size_t>(id) * static_cast<std::size_t>(stride_);
  for (int s = 0; s < stride_; ++s) p[slot_axes_[s]] = coords_[base + static_cast<std::size_t>(s)];
  return p;
}

double Program::feed(SegmentId id) const noexcept {
  const Move& m = moves_[id];
  if (m.kind == MoveKind::Traverse) return 0.0;
  if (m.kind == MoveKind::Arc) return feeds_[arcs_[m.param].feed];
  return feeds_[m.param];
}

std::uint32_t Program::file_of(SegmentId id) const {
  const std::uint32_t ctx = moves_[id].context;
  return ctx == 0 ? 0 : sources_->context_info(ctx).body_file;
}

SegmentId Program::append(const Move& m, const Pose& end) {
  append(end) = m;
  return moves_.size() - 1;
}

// In place: a move or pose built by the caller and then copied whole costs a failed store
// forwarding on every move (the wide loads of the copy meet narrow stores still in flight).
Move& Program::append(const Pose& end) {
  if ((moves_.size() & (decltype(moves_)::kChunk - 1)) == 0)
    move_floors_.push_back({arcs_.empty() ? 0 : arcs_.size() - 1, feeds_.empty() ? 0 : feeds_.size() - 1});
  coords_.append_with(static_cast<std::size_t>(stride_), [&](std::size_t s) { return end[slot_axes_[s]]; });
  return moves_.append_slot();
}

std::uint32_t Program::add_arc(const ArcGeometry& a) {
  arcs_.push_back(a);
  return static_cast<std::uint32_t>(arcs_.size() - 1);
}

std::uint32_t Program::add_feed(double value) {
  feeds_.push_back(value);
  return static_cast<std::uint32_t>(feeds_.size() - 1);
}

std::uint32_t Program::add_text(std::string s) {
  texts_.push_back(std::move(s));
  return static_cast<std::uint32_t>(first_text_ + texts_.size() - 1);
}

std::uint32_t Program::add_action_pose(const Pose& p) {
  action_poses_.push_back(p);
  return static_cast<std::uint32_t>(action_poses_.size() - 1);
}

void Program::add_action(const Action& a) {
  if ((actions_.size() & (decltype(actions_)::kChunk - 1)) == 0) {
    const std::size_t texts = first_text_ + texts_.size();
    action_floors_.push_back({texts == 0 ? 0 : texts - 1, action_poses_.empty() ? 0 : action_poses_.size() - 1});
  }
  actions_.push_back(a);
}

void Program::release_before(std::size_t move, std::size_t action) {
  // Keep the predecessor of the first move kept: its end is that move's start.
  const std::size_t keep_move = move == 0 ? 0 : std::min(move, moves_.size()) - 1;
  const std::size_t held = moves_.release_before(keep_move);
  coords_.release_before(held * static_cast<std::size_t>(stride_));
  const std::size_t chunk = held / decltype(moves_)::kChunk;
  if (chunk < move_floors_.size()) {
    arcs_.release_before(move_floors_[chunk].arc);
    feeds_.release_before(move_floors_[chunk].feed);
  }
  const std::size_t held_actions = actions_.release_before(std::min(action, actions_.size()));
  const std::size_t action_chunk = held_actions / decltype(actions_)::kChunk;
  if (action_chunk < action_floors_.size()) {
    const ActionFloor& f = action_floors_[action_chunk];
    while (first_text_ < f.text && !texts_.empty()) {
      texts_.pop_front();
      ++first_text_;
    }
    action_poses_.release_before(f.pose);
  }
}

void Program::note_split(SegmentId segment, std::size_t first_move, std::size_t moves) {
  if (moves <= 1) return;
  // The same split again with more moves (a segment noted as it grows): the last note grows.
  if (!splits_.empty() && splits_.back().segment == segment && splits_.back().first_move == first_move) {
    Split& s = splits_.back();
    s.extra += moves - s.moves;
    s.moves = moves;
    return;
  }
  const std::size_t before = splits_.empty() ? 0 : splits_.back().extra;
  splits_.push_back({segment, first_move, moves, before + moves - 1});
}

SegmentId Program::segment_of(std::size_t move) const noexcept {
  // The last split that starts at or before `move`.
  const auto it = std::upper_bound(splits_.begin(), splits_.end(), move,
                                   [](std::size_t m, const Split& s) { return m < s.first_move; });
  if (it == splits_.begin()) return first_segment_ + move;
  const Split& s = *(it - 1);
  if (move < s.first_move + s.moves) return s.segment;
  return first_segment_ + move - s.extra;
}

std::size_t Program::first_move_of(SegmentId segment) const noexcept {
  const auto it = std::upper_bound(splits_.begin(), splits_.end(), segment,
                                   [](SegmentId id, const Split& s) { return id < s.segment; });
  if (it == splits_.begin()) return static_cast<std::size_t>(segment - first_segment_);
  const Split& s = *(it - 1);
  if (segment == s.segment) return s.first_move;
  return static_cast<std::size_t>(segment - first_segment_) + s.extra;
}

std::size_t Program::moves_of(SegmentId segment) const noexcept {
  const auto it = std::lower_bound(splits_.begin(), splits_.end(), segment,
                                   [](const Split& s, SegmentId id) { return s.segment < id; });
  return it != splits_.end() && it->segment == segment ? it->moves : 1;
}

std::size_t Program::memory_bytes() const noexcept {
  std::size_t bytes = moves_.capacity_bytes() + coords_.capacity_bytes() + arcs_.capacity_bytes();
  bytes += feeds_.capacity_bytes() + actions_.capacity_bytes();
  bytes += action_poses_.capacity_bytes() + splits_.capacity() * sizeof(Split);
  for (const auto& t : texts_) bytes += t.capacity() + sizeof(std::string);
  return bytes;
}

}  // namespace opencnc::canon
