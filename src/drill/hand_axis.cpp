// SPDX-License-Identifier: GPL-3.0-or-later
// The hand-axis pass: moves of hand-fed axes become waits for the operator (HandAxisWait actions),
// move by move as the builder appends them.
#include "opencnc/drill/hand_axis.hpp"

#include <fmt/format.h>

#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::drill {

namespace {

using canon::Action;
using canon::ActionKind;
using canon::Move;
using canon::MoveKind;

std::string file_name(const canon::Program& p, canon::SegmentId id) {
  const std::uint32_t f = p.file_of(id);
  return f < p.sources().file_count() ? p.sources().file(f) : std::string();
}

}  // namespace

HandAxes hand_axes(const config::MachineProfile& profile) {
  HandAxes h;
  for (const config::AxisProfile& a : profile.axes) {
    if (!a.manual()) continue;
    h.axes.set(a.axis);
    h.min_limit[static_cast<std::size_t>(index(a.axis))] = a.min_limit;
    h.max_limit[static_cast<std::size_t>(index(a.axis))] = a.max_limit;
  }
  return h;
}

void HandAxisFilter::process(canon::Program& program) {
  if (!hand_.any()) return;
  if (!started_) {
    started_ = true;
    next_ = 0;
    fixed_ = programmed_ = program.start();
  }
  for (; next_ < program.size(); ++next_) process_move(program, next_);
}

// Whether an arc in `plane` moves a hand axis along its circle.
bool HandAxisFilter::in_plane(canon::Plane plane) const noexcept {
  const canon::PlaneAxes a = canon::plane_axes(plane);
  return hand_.axes.has(static_cast<Axis>(a.first)) || hand_.axes.has(static_cast<Axis>(a.second));
}

void HandAxisFilter::fail(const canon::Program& program, canon::SegmentId id, std::string message) {
  failures_.error(file_name(program, id), program.move(id).line, 0, std::move(message), "control.hand-axis");
}

// One move: its hand coordinates back to the fixed ones, and a wait for each hand axis it moved
// (a retract before the table's motion — the action stands before this move —, a plunge after it
// — before the next move).
void HandAxisFilter::process_move(canon::Program& program, canon::SegmentId id) {
  const Move& m = program.move(id);
  const Pose to = program.end(id);
  const bool arc_in_plane = m.kind == MoveKind::Arc && in_plane(program.arc(id).plane);
  bool driven = false, hand = arc_in_plane;
  std::string letters;
  for (int i = 0; i < kAxisCount; ++i) {
    const auto a = static_cast<Axis>(i);
    const bool moved = to[i] != programmed_[i];
    if (hand_.axes.has(a)) {
      if (moved || arc_in_plane) letters += letter(a);
      hand = hand || moved;
    } else {
      driven = driven || to[i] != program.start_of(id)[i];
    }
  }
  const Pose asked = programmed_;
  for (int i = 0; i < kAxisCount; ++i) {
    if (!hand_.axes.has(static_cast<Axis>(i))) continue;
    programmed_[i] = to[i];
    program.set_end_coord(id, static_cast<Axis>(i), fixed_[i]);
  }
  if (!hand) return;
  if (m.kind == MoveKind::Arc || m.kind == MoveKind::Probe || m.kind == MoveKind::RigidTap ||
      (m.flags & canon::kSpindleSynced)) {
    const char* what = m.kind == MoveKind::Arc ? (arc_in_plane ? "arc" : "helix") : "move";
    fail(program, id,
         fmt::format(
             "this {} moves the hand-fed axis {}: only straight moves of a hand axis can be waited for", what,
             letters));
    return;
  }
  std::array<Action, kAxisCount> after{};
  int plunges = 0;
  for (int i = 0; i < kAxisCount; ++i) {
    const auto axis = static_cast<Axis>(i);
    if (!hand_.axes.has(axis) || to[i] == asked[i]) continue;
    const auto ui = static_cast<std::size_t>(i);
    if (to[i] < hand_.min_limit[ui] - 1e-9 || to[i] > hand_.max_limit[ui] + 1e-9) {
      fail(program, id,
           fmt::format("the program wants the hand-fed axis {} at {:.4f}, beyond its soft limits [{}, {}]",
                       letter(axis), to[i], hand_.min_limit[ui], hand_.max_limit[ui]));
      continue;
    }
    Action a;
    a.kind = ActionKind::HandAxisWait;
    a.index = i;
    a.index2 = to[i] > asked[i] ? 1 : 0;
    a.value = to[i];
    a.context = m.context;
    a.line = m.line;
    if (a.index2 > 0 || !driven) {
      a.before_move = static_cast<std::uint32_t>(id);
      program.add_action(a);
    } else {
      a.before_move = static_cast<std::uint32_t>(id + 1);
      after[static_cast<std::size_t>(plunges++)] = a;
    }
  }
  for (int k = 0; k < plunges; ++k) program.add_action(after[static_cast<std::size_t>(k)]);
}

}  // namespace opencnc::drill
