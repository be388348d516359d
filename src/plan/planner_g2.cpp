// SPDX-License-Identifier: GPL-3.0-or-later
// Curvature-continuous (G2) corners for jerk-limited machines: quintic blends within the tolerance,
// transitions where tangent pieces change curvature, and runs of short moves joined into one
// smooth curve (shared junctions).
//
// With jerk limits a step of curvature is a step of axis acceleration (v²·Δκ) that only a low
// speed can make acceptable. So every corner gets a quintic Bézier that matches the pieces' point,
// first and second derivative at both ends (make_g2_curve), and so does every tangent junction
// where the curvature jumps (a line into an arc). Between short moves a blend takes half of each
// move, and two blends meet at a move's midpoint: there they share a curvature, the mean of their
// own turning rates, instead of the line's zero, so that a run of short CAM segments is followed
// as one curve whose curvature follows the programmed shape rather than a chain of bumps.
#include <algorithm>
#include <cmath>

#include "opencnc/traj/path_eval.hpp"
#include "planner_impl.hpp"
#include "vec.hpp"

namespace opencnc::plan {

using detail::dot;
using detail::norm;
using detail::operator+;
using detail::operator-;
using detail::operator*;
using traj::BlockKind;
using traj::FeedClass;

namespace {

/// Curvature steps no larger than this relative to the path's scale count as none.
constexpr double kNoJump = 1e-9;

Pose unit(const Pose& v) {
  const double n = norm(v);
  return n > 0 ? (1.0 / n) * v : v;
}

/// Whether the curvature changes where `in` ends and `out` starts (both tangent there).
bool curvature_jumps(const MotionBlock& in, const MotionBlock& out) {
  const Pose k1 = traj::curvature_at(in, in.length), k2 = traj::curvature_at(out, 0.0);
  const double scale = std::max({norm(k1), norm(k2), 1.0 / std::max(in.length, out.length)});
  return norm(k2 - k1) > kNoJump * scale;
}

/// The straight line through the corner point `v` along `t`, from `v − len·t` to `v` (or from
/// `v` to `v + len·t`): the pieces a unit blend is measured against.
MotionBlock unit_line(const Pose& from, const Pose& to) {
  MotionBlock l;
  detail::make_line(from, to, l);
  return l;
}

}  // namespace

void Planner::Impl::release_held() {
  if (!held) return;
  emit_path(held->curve, kInf);
  held.reset();
}

// `a` runs into the next move without a blend (tangent, or a step the window limits).
void Planner::Impl::pass_through(Element& a) {
  release_held();
  emit_path(a.b, a.junction);
  emit_reports();
}

// An independent blend of the corner: symmetric, as large as the two moves (half of each), the
// tolerance and the speed it must be taken at allow (no larger than the speed needs).
bool Planner::Impl::g2_blend(const Element& a, const Element& e, const detail::CornerTurn& turn, double tol,
                             detail::Blend& out) const {
  const double avail_a = std::min(0.5 * a.orig_length, a.b.length);
  const double avail_e = std::min(0.5 * e.orig_length, e.b.length);
  const detail::BlendNeed need = blend_need(a.b, e.b);
  const auto build = [&](double d) {
    return detail::make_g2_curve(detail::join_at(a.b, a.b.length - d), detail::join_at(e.b, d), out.curve);
  };
  double d_max = std::min(avail_a, avail_e);
  if (a.b.kind == BlockKind::Line && e.b.kind == BlockKind::Line && turn.angle > detail::kTangentAngle) {
    // Between two lines the blend only scales with d: its deviation grows as d, the centripetal
    // and jerk bounds of its polygon as 1/d and 1/d², so one unit blend sizes it.
    const Pose v = detail::end_point(a.b);
    if (!detail::make_g2_curve(detail::join_at(unit_line(v - turn.in, v), 0.0),
                               detail::join_at(unit_line(v, v + turn.out), 1.0), out.curve)) {
      // (a corner too sharp for the curve: no blend)
      return false;
    }
    // The symmetric blend is farthest from both lines at its middle (checked numerically for
    // turns of 1° to 179°): its deviation grows as d from there.
    // Its middle is also where it passes the corner, |mid − v| from it (a point of the curve:
    // the corner is at most that far from it).
    const Pose mid = traj::position_at(out.curve, 0.5 * out.curve.length);
    const double dev = std::max({detail::distance_to(unit_line(v - 2.0 * turn.in, v), mid),
                                 detail::distance_to(unit_line(v, v + 2.0 * turn.out), mid), norm(mid - v)});
    if (tol > 0 && dev > 0) d_max = std::min(d_max, tol / dev);
    double d1[kAxisCount], d2[kAxisCount], d3[kAxisCount];
    detail::derivative_bounds(out.curve, d1, d2, d3);
    double d_need = 0;
    const double v_top = need.speed;
    for (int i = 0; i < kAxisCount; ++i) {
      const AxisLimits& l = limits[i];
      if (!limits.axes.has(static_cast<Axis>(i))) continue;
      d_need = std::max(d_need, v_top * v_top * d2[i] / (need.share * l.max_acceleration));
      if (l.max_jerk > 0)
        d_need = std::max(d_need, std::sqrt(v_top * v_top * v_top * d3[i] / (0.5 * l.max_jerk)));
    }
    d_max = std::min(d_max, d_need);
    if (!(d_max >= detail::kMinLength) || !build(d_max)) return false;
    out.trim_in = out.trim_out = d_max;
    return true;
  }
  // Arcs involved, or a tangent junction whose curvature jumps: sized by bisection on the
  // tolerance. A transition need not be longer than what ramps the curvature at the top speed
  // within half the jerk: v³·|Δκ|/ℓ ≤ J/2.
  if (turn.angle <= detail::kTangentAngle) {
    const double jump = norm(traj::curvature_at(e.b, 0.0) - traj::curvature_at(a.b, a.b.length));
    double j_min = kInf;
    for (int i = 0; i < kAxisCount; ++i) {
      if (limits.axes.has(static_cast<Axis>(i)) && limits[i].max_jerk > 0)
        j_min = std::min(j_min, limits[i].max_jerk);
    }
    // (a step of |dp/ds| alone, with no curvature jump, takes what the tolerance allows)
    if (j_min < kInf && jump > 0)
      d_max = std::min(d_max, need.speed * need.speed * need.speed * jump / j_min);
  }
  if (!(d_max >= detail::kMinLength)) return false;
  const auto ok = [&](double d) {
    return build(d) && (tol <= 0 || detail::blend_within(out.curve, a.b, e.b, tol));
  };
  double d = d_max;
  if (!ok(d)) {
    double lo = 0, hi = d_max;
    for (int i = 0; i < 30 && hi - lo > 1e-6 * d_max; ++i) {
      const double mid = 0.5 * (lo + hi);
      (ok(mid) ? lo : hi) = mid;
    }
    d = lo;
    if (!(d >= detail::kMinLength) || !ok(d)) return false;
  }
  out.trim_in = out.trim_out = d;
  return true;
}

// The held blend ends where this one would start (each takes the whole of the move between
// them): let them meet with a common curvature, the mean of their turning rates across that
// point, as a smooth curve through the moves would have. Kept only if both stay within their
// tolerances; otherwise they meet with the move's own curvature.
bool Planner::Impl::share_junction(const Element& a, const Element& e, double tol, detail::Blend& blend) {
  if (!held || blend.trim_in < a.b.length * (1 - 1e-9)) return false;
  detail::JoinPoint j = detail::join_at(a.b, 0.0);
  const Pose t = unit(j.d1);
  const detail::JoinPoint end = detail::join_at(e.b, blend.trim_out);
  const Pose own_turn = (1.0 / (a.b.length + blend.trim_out)) * (unit(end.d1) - t);
  Pose k = 0.5 * (held->mean_turn + own_turn);
  k = k - dot(k, t) * t;
  j.d2 = (1.0 / dot(j.d1, j.d1)) * k;
  MotionBlock before_curve = held->curve, next_curve = blend.curve;
  if (!detail::make_g2_curve(held->from, j, before_curve)) return false;
  if (held->tolerance > 0 && !detail::blend_within(before_curve, held->before, held->after, held->tolerance))
    return false;
  if (!detail::make_g2_curve(j, end, next_curve)) return false;
  if (tol > 0 && !detail::blend_within(next_curve, held->after, e.b, tol)) return false;
  held->curve = before_curve;  // the same identity, the new shape
  blend.curve = next_curve;
  blend.trim_in = a.b.length;
  return true;
}

bool Planner::Impl::corner_g2(Element& a, Element& e) {
  if (a.stop_after || a.mode == canon::MotionControl::ExactStop) return false;
  if ((a.b.feed_class == FeedClass::SpindleSync) != (e.b.feed_class == FeedClass::SpindleSync)) return false;
  const detail::CornerTurn turn = detail::corner_turn(a.b, e.b);
  const bool kink = turn.angle > detail::kTangentAngle;
  const bool scale_step = !kink && !detail::same_speed_scale(a.b, e.b);  // |dp/ds| would step
  if (!kink && !scale_step && !curvature_jumps(a.b, e.b)) {
    pass_through(a);
    return true;
  }
  if (kink && (a.mode != canon::MotionControl::Continuous || turn.angle >= detail::kReversalAngle))
    return false;
  double tol = 0;
  if (a.tolerance > 0) tol = a.tolerance - std::max(a.merge_deviation, e.merge_deviation);
  detail::Blend blend;
  const bool smooth = a.mode == canon::MotionControl::Continuous && (a.tolerance <= 0 || tol > 0) &&
                      g2_blend(a, e, turn, tol, blend);
  if (!smooth) {
    if (!kink && (!scale_step || detail::speed_scale_step(a.b, e.b) <= detail::kSpeedScaleSlack)) {
      pass_through(a);  // a curvature step stays: the window's step limit takes it
      return true;
    }
    if (!kink) {
      release_held();
      return false;  // |dp/ds| would step and nothing may smooth it: stop there
    }
    release_held();
    return corner_g1(a, e);  // a G1 blend (steps included) or a stop
  }
  if (kink && !blend_pays(a, e, blend)) {
    release_held();
    return false;
  }
  const bool shared = share_junction(a, e, tol, blend);
  release_held();
  const MotionBlock a_whole = a.b;  // the piece the new blend leaves, up to the corner
  if (!shared) {
    detail::trim_end(a.b, blend.trim_in);
    if (a.b.length >= detail::kMinLength) emit_path(a.b, a.junction);
  }
  emit_reports();
  MotionBlock& c = blend.curve;
  c.flags = static_cast<std::uint8_t>((a.b.flags & e.b.flags) | traj::kBlend);
  c.segment = a.b.segment_last;
  c.segment_first = a.b.segment_first;
  c.segment_last = e.b.segment_last;
  c.line = a.b.line;
  c.context = a.b.context;
  c.segment_offset = a.b.segment == a.b.segment_last ? a.b.segment_offset + (shared ? 0.0 : a.b.length) : 0.0;
  if (a.b.feed_class == e.b.feed_class) {
    c.feed_class = a.b.feed_class;
    c.feed = std::min(a.b.feed, e.b.feed);
  } else {  // rapid into feed or back: the feed side rules the blend
    const MotionBlock& f = a.b.feed_class == FeedClass::Rapid ? e.b : a.b;
    c.feed_class = f.feed_class;
    c.feed = f.feed;
  }
  Held h;
  h.curve = c;
  h.from = detail::join_at(c, 0.0);
  h.before = a_whole;
  h.after = e.b;
  h.tolerance = tol;
  const Pose t0 = unit(traj::tangent_at(c, 0.0)), t1 = unit(traj::tangent_at(c, c.length));
  h.mean_turn = (1.0 / (blend.trim_in + blend.trim_out)) * (t1 - t0);
  held = h;
  detail::trim_start(e.b, blend.trim_out);
  ++stats.blends;
  return true;
}

}  // namespace opencnc::plan
