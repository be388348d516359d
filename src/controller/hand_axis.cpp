// SPDX-License-Identifier: GPL-3.0-or-later
// The hand-axis pass: moves of hand-fed axes become waits for the operator (HandAxisWait actions).
#include "opencnc/controller/hand_axis.hpp"

#include <fmt/format.h>

#include <unordered_map>
#include <vector>

namespace opencnc::control {

namespace {

using canon::Action;
using canon::ActionKind;
using canon::Move;
using canon::MoveKind;

std::string file_name(const canon::Program& p, canon::SegmentId id) {
  const std::uint32_t f = p.file_of(id);
  return f < p.sources().file_count() ? p.sources().file(f) : std::string();
}

/// Waits a move needs, before or after its motion.
struct Waits {
  std::vector<Action> before, after;
};

class Pass {
 public:
  Pass(const canon::Program& in, const HandAxes& hand, Diagnostics& diags)
      : in_(in), hand_(hand), diags_(diags), out_(std::make_shared<canon::Program>(in.axes())) {}

  std::shared_ptr<canon::Program> run() {
    out_->set_sources(in_.sources_ptr());
    out_->set_start(in_.start());
    const std::vector<Action>& actions = in_.actions();
    std::size_t next = 0;
    std::vector<Action> pending_after;  // the previous move's plunges: before this move's actions
    for (canon::SegmentId id = 0; id < in_.size(); ++id) {
      emit(pending_after);
      while (next < actions.size() && actions[next].before_move <= id) copy_action(actions[next++]);
      Waits w = waits_of(id);
      emit(w.before);
      copy_move(id);
      pending_after = std::move(w.after);
    }
    emit(pending_after);
    while (next < actions.size()) copy_action(actions[next++]);
    return diags_.error_count() == errors_before_ ? out_ : nullptr;
  }

  std::size_t waits() const { return waits_; }

 private:
  void emit(const std::vector<Action>& waits) {
    waits_ += waits.size();
    for (Action a : waits) {
      a.before_move = static_cast<std::uint32_t>(out_->size());
      out_->add_action(a);
    }
  }

  void copy_action(Action a) {
    const bool has_text =
        a.kind == ActionKind::Message || a.kind == ActionKind::Comment || a.kind == ActionKind::WaitInput;
    if (has_text) {
      auto it = texts_.find(a.text);
      if (it == texts_.end()) it = texts_.emplace(a.text, out_->add_text(in_.text(a.text))).first;
      a.text = it->second;
    }
    if (a.kind == ActionKind::ToolLengthOffset || a.kind == ActionKind::WorkOffset ||
        a.kind == ActionKind::G92Offset)
      a.pose = out_->add_action_pose(in_.action_pose(a.pose));
    out_->add_action(a);
  }

  void fail(canon::SegmentId id, std::string message) {
    diags_.error(file_name(in_, id), in_.move(id).line, 0, std::move(message), "control.hand-axis");
  }

  /// The waits that stand for move `id`'s motion of the hand axes.
  Waits waits_of(canon::SegmentId id) {
    Waits w;
    const Move& m = in_.move(id);
    const Pose from = in_.start_of(id), to = in_.end(id);
    bool driven = false, hand = false;
    for (int i = 0; i < kAxisCount; ++i) {
      if (from[i] == to[i]) continue;
      (hand_.axes.has(static_cast<Axis>(i)) ? hand : driven) = true;
    }
    // An arc in a plane of a hand axis moves it even when it ends where it started.
    const bool hand_plane = m.kind == MoveKind::Arc && in_plane(in_.arc(id).plane);
    hand = hand || hand_plane;
    if (!hand) return w;
    if (m.kind == MoveKind::Arc || m.kind == MoveKind::Probe || m.kind == MoveKind::RigidTap ||
        (m.flags & canon::kSpindleSynced)) {
      fail(id, fmt::format("this {} moves the hand-fed axis {}: only straight moves of a hand axis can be "
                           "waited for",
                           m.kind == MoveKind::Arc ? (hand_plane ? "arc" : "helix") : "move", axis_letters(from, to, id)));
      return w;
    }
    for (int i = 0; i < kAxisCount; ++i) {
      const auto axis = static_cast<Axis>(i);
      if (!hand_.axes.has(axis) || from[i] == to[i]) continue;
      const auto ui = static_cast<std::size_t>(i);
      if (to[i] < hand_.min_limit[ui] - 1e-9 || to[i] > hand_.max_limit[ui] + 1e-9) {
        fail(id, fmt::format("the program wants the hand-fed axis {} at {:.4f}, beyond its soft limits [{}, {}]",
                             letter(axis), to[i], hand_.min_limit[ui], hand_.max_limit[ui]));
        continue;
      }
      Action a;
      a.kind = ActionKind::HandAxisWait;
      a.index = i;
      a.index2 = to[i] > from[i] ? 1 : 0;
      a.value = to[i];
      a.context = m.context;
      a.line = m.line;
      // A retract comes before the table moves, a plunge after it (a move of the hand axis alone:
      // it is the wait).
      (a.index2 > 0 || !driven ? w.before : w.after).push_back(a);
    }
    return w;
  }

  /// Whether an arc in `plane` moves a hand axis along its circle.
  bool in_plane(canon::Plane plane) const {
    const auto has = [&](Axis a) { return hand_.axes.has(a); };
    switch (plane) {
      case canon::Plane::XY:
        return has(Axis::X) || has(Axis::Y);
      case canon::Plane::YZ:
        return has(Axis::Y) || has(Axis::Z);
      case canon::Plane::XZ:
        return has(Axis::X) || has(Axis::Z);
      case canon::Plane::UV:
        return has(Axis::U) || has(Axis::V);
      case canon::Plane::VW:
        return has(Axis::V) || has(Axis::W);
      case canon::Plane::UW:
        return has(Axis::U) || has(Axis::W);
    }
    return false;
  }

  std::string axis_letters(const Pose& from, const Pose& to, canon::SegmentId id) const {
    std::string s;
    for (int i = 0; i < kAxisCount; ++i) {
      const auto a = static_cast<Axis>(i);
      if (!hand_.axes.has(a)) continue;
      const bool on_circle = in_.move(id).kind == MoveKind::Arc && in_plane(in_.arc(id).plane);
      if (from[i] != to[i] || on_circle) s += letter(a);
    }
    return s;
  }

  void copy_move(canon::SegmentId id) {
    Move m = in_.move(id);
    Pose end = in_.end(id);
    for (int i = 0; i < kAxisCount; ++i) {
      if (hand_.axes.has(static_cast<Axis>(i))) end[i] = in_.start()[i];
    }
    const double f = in_.feed(id);
    if (f != last_feed_ || out_->size() == 0) {
      feed_index_ = out_->add_feed(f);
      last_feed_ = f;
    }
    if (m.kind == MoveKind::Arc) {
      canon::ArcGeometry g = in_.arc(id);
      g.feed = feed_index_;
      m.param = out_->add_arc(g);
    } else {
      m.param = feed_index_;
    }
    out_->append(m, end);
  }

  const canon::Program& in_;
  const HandAxes& hand_;
  Diagnostics& diags_;
  std::size_t errors_before_ = diags_.error_count();
  std::shared_ptr<canon::Program> out_;
  std::unordered_map<std::uint32_t, std::uint32_t> texts_;
  double last_feed_ = -1;
  std::uint32_t feed_index_ = 0;
  std::size_t waits_ = 0;
};

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

std::shared_ptr<const canon::Program> hand_axis_program(std::shared_ptr<const canon::Program> program,
                                                        const HandAxes& hand, Diagnostics& diags) {
  if (!program || !hand.any()) return program;
  Pass pass(*program, hand, diags);
  std::shared_ptr<canon::Program> out = pass.run();
  if (out && pass.waits() == 0) return program;  // nothing of it was the operator's
  return out;
}

}  // namespace opencnc::control
