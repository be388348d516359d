// SPDX-License-Identifier: GPL-3.0-or-later
// CompPath: plane coordinates, the lathe tool origin, and the queue of held moves (hold,
// release, settle a corner with LinuxCNC's gouge checks).
#include "comp_path.hpp"

#include <cmath>

#include "arc_math.hpp"
#include "gcode_error.hpp"
#include "opencnc/canon/arc_geometry.hpp"

namespace opencnc::gcode::comp {

CompPath::CompPath(ExecContext& ctx)
    : ctx_(ctx),
      st_(ctx.state()),
      plane_(st_.modal.plane),
      a1_(canon::plane_axes(plane_).first),  // comp runs in G17 and G18 only
      a2_(canon::plane_axes(plane_).second),
      a3_(canon::plane_axes(plane_).normal),
      left_(st_.modal.cutter_comp == CutterComp::Left),
      radius_(st_.modal.comp_radius) {}

void CompPath::current(double& c1, double& c2, double& c3) const noexcept {
  split(st_.position.current, c1, c2, c3);
}

void CompPath::programmed(double& p1, double& p2, double& p3) const noexcept {
  const auto& p = st_.position.programmed;
  p1 = p[static_cast<std::size_t>(a1_)];
  p2 = p[static_cast<std::size_t>(a2_)];
  p3 = p[static_cast<std::size_t>(a3_)];
}

void CompPath::split(const Pose& p, double& p1, double& p2, double& p3) const noexcept {
  p1 = p[a1_];
  p2 = p[a2_];
  p3 = p[a3_];
}

void CompPath::place(Pose& p, double p1, double p2, double p3) const noexcept {
  p[a1_] = p1;
  p[a2_] = p2;
  p[a3_] = p3;
}

Pose CompPath::pose(double e1, double e2, double e3, const Pose& others) const noexcept {
  Pose p = others;
  place(p, e1, e2, e3);
  return p;
}

void CompPath::moved_to(double e1, double e2, double e3, const Pose& end) noexcept {
  st_.position.current = pose(e1, e2, e3, end);
}

void CompPath::set_programmed(double p1, double p2, double p3) noexcept {
  auto& p = st_.position.programmed;
  p[static_cast<std::size_t>(a1_)] = p1;
  p[static_cast<std::size_t>(a2_)] = p2;
  p[static_cast<std::size_t>(a3_)] = p3;
}

const CompQueuedMove* CompPath::held_front() const noexcept {
  return st_.comp.queued.empty() ? nullptr : &st_.comp.queued.front();
}

const CompQueuedMove& CompPath::front() const noexcept {
  return st_.comp.queued.empty() ? st_.comp.last_first : st_.comp.queued.front();
}

// Compensation steers the centre of the tool's nose radius; a lathe tool's controlled point
// is where its two edges' tangents meet, one radius off in X and/or Z depending on the
// orientation (LinuxCNC's tool orientations 1..8; 0 and 9 are centred).
void CompPath::lathe_shift(double& s1, double& s2) const noexcept {
  s1 = s2 = 0;
  if (plane_ != canon::Plane::XZ) return;
  const int o = st_.modal.comp_orientation;
  const double r = radius_;
  if (o == 2 || o == 7 || o == 3) s1 = -r;  // Z
  if (o == 1 || o == 5 || o == 4) s1 = r;
  if (o == 2 || o == 6 || o == 1) s2 = -r;  // X
  if (o == 3 || o == 8 || o == 4) s2 = r;
}

void CompPath::queue_line(bool rapid, double dir1, double dir2, double e1, double e2, double e3,
                          const Pose& others) {
  double s1, s2;
  lathe_shift(s1, s2);
  const Pose end = pose(e1 + s1, e2 + s2, e3, others);
  ctx_.open_queue();
  if (rapid)
    ctx_.output().straight_traverse(0, end);
  else
    ctx_.output().straight_feed(0, end);
  CompQueuedMove q;
  q.kind = rapid ? CompQueuedMove::Kind::Traverse : CompQueuedMove::Kind::Feed;
  q.dir1 = dir1;
  q.dir2 = dir2;
  st_.comp.queued.push_back(q);
}

void CompPath::queue_arc(double sweep, double e1, double e2, double c1, double c2, int turn, double e3,
                         const Pose& others) {
  double s1, s2;
  lathe_shift(s1, s2);
  canon::ArcFeed arc;
  arc.plane = plane_;
  arc.first_end = e1 + s1;
  arc.second_end = e2 + s2;
  arc.first_center = c1 + s1;
  arc.second_center = c2 + s2;
  arc.rotation = turn;
  arc.axis_end = e3;
  arc.end = pose(arc.first_end, arc.second_end, e3, others);
  ctx_.open_queue();
  ctx_.output().arc_feed(0, arc);
  CompQueuedMove q;
  q.kind = CompQueuedMove::Kind::Arc;
  q.center1 = c1;
  q.center2 = c2;
  q.end1 = e1;
  q.end2 = e2;
  q.turn = turn;
  q.sweep = sweep;
  st_.comp.queued.push_back(q);
}

void CompPath::release() {
  if (!st_.comp.queued.empty()) st_.comp.last_first = st_.comp.queued.front();
  ctx_.flush_queue();
  st_.comp.queued.clear();
  st_.comp.start_valid = false;
}

void CompPath::set_start(double p1, double p2) noexcept {
  st_.comp.start1 = p1;
  st_.comp.start2 = p2;
  st_.comp.start_valid = true;
}

void CompPath::settle(double p1, double p2) {
  CompState& cs = st_.comp;
  if (cs.queued.empty()) return;
  // How much further (rad) a shortened arc may sweep than programmed: LinuxCNC's allowance,
  // 0.0254 with millimetre programs and 0.001 with inch ones.
  const double sweep_slack = st_.modal.units == canon::Units::Mm ? 0.0254 : 0.001;
  for (CompQueuedMove& q : cs.queued) {
    if (q.kind == CompQueuedMove::Kind::Arc) {
      // The new end must lie on the same circle; an arc may shrink but not grow.
      const double r_old = std::hypot(q.end1 - q.center1, q.end2 - q.center2);
      const double r_new = std::hypot(p1 - q.center1, p2 - q.center2);
      const double sweep = find_turn(cs.start1, cs.start2, q.center1, q.center2, q.turn, p1, p2);
      if (std::fabs(r_old - r_new) > 0.01)
        fail(ErrorCode::CompArcOffCircle,
             "cutter compensation cannot end the arc before this corner on its circle (radius {:.4f}, corner "
             "at {:.4f})",
             r_old, r_new);
      if (q.sweep != 0 && cs.start_valid && std::fabs(sweep) > std::fabs(q.sweep) + sweep_slack)
        fail(ErrorCode::CompGouge, "the tool cannot reach the inside corner after this arc without gouging");
      q.end1 = p1;
      q.end2 = p2;
    } else if (cs.start_valid && q.dir1 * (p1 - cs.start1) + q.dir2 * (p2 - cs.start2) < 0) {
      // Backing out of the corner ran past the start of the move: the tool would cut back.
      fail(ErrorCode::CompGouge, "the tool cannot reach the inside corner after this {} without gouging",
           q.kind == CompQueuedMove::Kind::Traverse ? "rapid move" : "straight move");
    }
  }
  double s1, s2;
  lathe_shift(s1, s2);
  ctx_.move_queued_end(plane_, p1 + s1, p2 + s2);
  release();
  set_start(p1, p2);
}

}  // namespace opencnc::gcode::comp
