// SPDX-License-Identifier: GPL-3.0-or-later
// Storage of the expanded program: 16-byte moves, strided poses, side tables.
#include "opencnc/canon/program.hpp"

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
  moves_.push_back(m);
  double values[kAxisCount];
  for (int s = 0; s < stride_; ++s) values[s] = end[slot_axes_[s]];
  coords_.append(values, static_cast<std::size_t>(stride_));
  return moves_.size() - 1;
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
  return static_cast<std::uint32_t>(texts_.size() - 1);
}

std::uint32_t Program::add_action_pose(const Pose& p) {
  action_poses_.push_back(p);
  return static_cast<std::uint32_t>(action_poses_.size() - 1);
}

std::size_t Program::memory_bytes() const noexcept {
  std::size_t bytes = moves_.capacity_bytes() + coords_.capacity_bytes() + arcs_.capacity_bytes();
  bytes += feeds_.capacity() * sizeof(double) + actions_.capacity() * sizeof(Action);
  bytes += action_poses_.capacity() * sizeof(Pose);
  for (const auto& t : texts_) bytes += t.capacity() + sizeof(std::string);
  return bytes;
}

}  // namespace opencnc::canon
