// SPDX-License-Identifier: GPL-3.0-or-later
// Trajectory metrics: finite-difference derivatives, limit violations, contour error.
#include "opencnc/analysis/trace_checker.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/core/minimise.hpp"
#include "opencnc/core/vec3.hpp"

namespace opencnc::analysis {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr int kLinear[] = {0, 1, 2, 6, 7, 8};

double linear_distance(const Pose& a, const Pose& b) {
  double s = 0;
  for (int i : kLinear) s += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(s);
}

double segment_distance(const Pose& a, const Pose& b, const Pose& p) {
  double ab2 = 0, t = 0;
  for (int i : kLinear) {
    ab2 += (b[i] - a[i]) * (b[i] - a[i]);
    t += (p[i] - a[i]) * (b[i] - a[i]);
  }
  t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
  double s = 0;
  for (int i : kLinear) {
    const double q = a[i] + t * (b[i] - a[i]) - p[i];
    s += q * q;
  }
  return std::sqrt(s);
}

double line_distance(const Pose& a, const Pose& b, const Pose& p) {
  double ab2 = 0, t = 0;
  for (int i : kLinear) {
    ab2 += (b[i] - a[i]) * (b[i] - a[i]);
    t += (p[i] - a[i]) * (b[i] - a[i]);
  }
  if (!(ab2 > 0)) return linear_distance(a, p);
  t /= ab2;
  double s = 0;
  for (int i : kLinear) {
    const double q = a[i] + t * (b[i] - a[i]) - p[i];
    s += q * q;
  }
  return std::sqrt(s);
}

/// Smallest f(a) for a within a quarter turn of a0 and inside [0, sweep] (golden section).
template <typename F>
double nearest_angle(F f, double a0, double sweep) {
  const double lo = std::max(0.0, a0 - 0.25 * std::numbers::pi),
               hi = std::min(sweep, a0 + 0.25 * std::numbers::pi);
  return std::min(golden_section(f, lo, hi, 40, 1e-12).f, f(a0));
}

// The turn k (whole, ≥ 0, unclamped above) whose point at the sample's own angle, a = phi + 2πk, is
// nearest to `p`. At that angle the distance is exact, and every part of it is linear in the arc's
// parameter f = a / sweep: the radius error |q| − (r0 + (r1 − r0) f), the rise along the normal and
// the axes outside the plane. Its square is a quadratic A f² + B f + C whose minimum is at
// f* = −B / 2A, and along the turns (a convex function sampled every 2π) the distance is smallest
// on one of the two turns around it: k0 = floor((f* sweep − phi) / 2π) or k0 + 1. So the nearest
// turn is found in O(1) instead of walking every turn of a helix (1000 evaluations per sample for
// 1000 turns).
double nearest_turn(const Pose& start, const Pose& end, const Pose& p, const Vec3& c, const Vec3& n, int b0,
                    double r0, double r1, double q_radius, double phi, double sweep) {
  double a2 = 0, b = 0;
  const auto term = [&](double alpha, double beta) {  // one component: alpha + beta f
    a2 += beta * beta;
    b += 2 * alpha * beta;
  };
  term(q_radius - r0, -(r1 - r0));
  const Vec3 s = take3(start, b0), e = take3(end, b0), pp = take3(p, b0);
  term(dot(s - c, n) - dot(pp - c, n), dot(e - s, n));
  for (int i : kLinear) {
    if (i < b0 || i > b0 + 2) term(start[i] - p[i], end[i] - start[i]);
  }
  if (!(a2 > 0)) return 0;  // a plain circle: every turn is as near
  const double f = std::clamp(-b / (2 * a2), 0.0, 1.0);
  return std::floor((f * sweep - phi) / kTwoPi);
}

// Distance to a programmed arc as LinuxCNC draws it: the radius changes linearly with the angle
// from the start radius to the end radius, the axial and other axes move linearly. The angle of
// the point gives the candidate (exact for a circle in its plane) on the nearest turn; where the
// arc also moves along its axis or changes radius, a golden-section search around it finds the
// nearest point.
double arc_distance(const canon::ArcGeometry& g, const Pose& start, const Pose& end, const Pose& p) {
  const int b0 = canon::plane_base(g.plane);
  const Vec3& n = g.normal;
  const Vec3& c = g.center;
  const auto in_plane = [&](const Pose& q) {
    const Vec3 v = take3(q, b0) - c;
    return v - dot(v, n) * n;
  };
  const Vec3 rs = in_plane(start), re = in_plane(end);
  const double r0 = std::sqrt(dot(rs, rs)), r1 = std::sqrt(dot(re, re));
  if (r0 <= 0) return linear_distance(start, p);
  const Vec3 e1 = (1 / r0) * rs;
  const Vec3 e2 = cross(n, e1);
  const double phi_end = std::atan2(dot(re, e2), dot(re, e1));
  const bool ccw = g.turns >= 0;
  const double sweep =
      std::fabs(canon::arc_sweep(phi_end, g.turns));  // its size: the angles below run with it

  const Vec3 q = in_plane(p);
  double phi = std::atan2(dot(q, e2), dot(q, e1));
  if (!ccw) phi = -phi;
  if (phi < 0) phi += kTwoPi;
  const auto point_at = [&](double a) {  // the arc at angle a ∈ [0, sweep]
    const double f = a / sweep;
    const double r = r0 + (r1 - r0) * f, ang = ccw ? a : -a;
    Pose x;
    for (int i = 0; i < kAxisCount; ++i) x[i] = start[i] + f * (end[i] - start[i]);
    const Vec3 axial = dot(take3(x, b0) - c, n) * n;
    for (int k = 0; k < 3; ++k)
      x[b0 + k] = c[k] + r * (std::cos(ang) * e1[k] + std::sin(ang) * e2[k]) + axial[k];
    return linear_distance(x, p);
  };
  double rest = 0;  // motion besides the circle: helix rise, other axes, radius change
  for (int i : kLinear) {
    if (i < b0 || i > b0 + 2) rest += std::fabs(end[i] - start[i]);
  }
  const Vec3 rise = take3(end, b0) - take3(start, b0);
  rest += std::fabs(dot(rise, n)) + std::fabs(r1 - r0);
  double best = std::min(linear_distance(start, p), linear_distance(end, p));
  const double last_turn = std::floor((sweep - phi) / kTwoPi);  // turns k with phi + 2πk on the arc
  if (last_turn >= 0) {
    const double k0 = nearest_turn(start, end, p, c, n, b0, r0, r1, std::sqrt(dot(q, q)), phi, sweep);
    for (double k = std::max(0.0, k0); k <= std::min(last_turn, k0 + 1); ++k) {
      const double a = phi + kTwoPi * k;
      const double same_angle = point_at(a);  // an upper bound; on the helix itself it is 0
      best =
          std::min(best, rest > 1e-12 && same_angle > 1e-9 ? nearest_angle(point_at, a, sweep) : same_angle);
    }
  }
  if (best <= 1e-9) return best;
  if (rest > 1e-12) {  // near the ends the nearest point of a helix may be at another angle
    const double quarter = 0.25 * std::numbers::pi;
    if (phi < quarter || phi > kTwoPi - quarter) best = std::min(best, nearest_angle(point_at, 0.0, sweep));
    const double to_end = std::remainder(phi - sweep, kTwoPi);
    if (std::fabs(to_end) < quarter) best = std::min(best, nearest_angle(point_at, sweep, sweep));
  }
  return best;
}

/// Distance from v to the path from b to c when the samples a, b, c (one period apart) lie on a
/// circle: the arc through them from b to c (exact for circular blends, and within a third-order
/// term of any smooth path); the chord when they are (nearly) in line.
double arc_distance(const Pose& a, const Pose& b, const Pose& c, const Pose& v) {
  Pose u{}, w{}, q{};
  for (int i : kLinear) {
    u[i] = a[i] - b[i];
    w[i] = c[i] - b[i];
    q[i] = v[i] - b[i];
  }
  const auto dot = [](const Pose& x, const Pose& y) {
    double s = 0;
    for (int i : kLinear) s += x[i] * y[i];
    return s;
  };
  const double uu = dot(u, u), ww = dot(w, w), uw = dot(u, w), det = uu * ww - uw * uw;
  if (!(det > 1e-12 * uu * ww)) return segment_distance(b, c, v);
  // The centre o = b + α·u + β·w is as far from a and c as from b: 2(o − b)·u = |u|², 2(o − b)·w = |w|².
  const double alpha = 0.5 * ww * (uu - uw) / det, beta = 0.5 * uu * (ww - uw) / det;
  Pose ob{};  // b − o
  for (int i : kLinear) ob[i] = -(alpha * u[i] + beta * w[i]);
  const double r = std::sqrt(dot(ob, ob));
  // Frame in the circle's plane: e1 towards b, e2 towards c's side; the arc from b to c is the
  // one that does not pass a (behind b).
  Pose e1{}, e2{}, oc{};
  for (int i : kLinear) {
    e1[i] = ob[i] / r;
    oc[i] = w[i] + ob[i];  // c − o
  }
  const double c1 = dot(oc, e1);
  for (int i : kLinear) e2[i] = oc[i] - c1 * e1[i];
  const double n2 = std::sqrt(dot(e2, e2));
  if (!(n2 > 0)) return segment_distance(b, c, v);
  for (int i : kLinear) e2[i] /= n2;
  const double sweep = std::atan2(dot(oc, e2), c1);  // in (0, π]
  Pose ov{};                                         // v − o
  for (int i : kLinear) ov[i] = q[i] + ob[i];
  const double p1 = dot(ov, e1), p2 = dot(ov, e2);
  const double psi = std::atan2(p2, p1);
  if (psi < 0 || psi > sweep) return std::min(linear_distance(b, v), linear_distance(c, v));
  const double in_plane = std::hypot(p1, p2), off2 = std::max(0.0, dot(ov, ov) - in_plane * in_plane);
  return std::sqrt((in_plane - r) * (in_plane - r) + off2);
}

}  // namespace

std::string TraceReport::summary() const {
  std::string s = fmt::format(
      "time {:.3f} s, path {:.3f} mm, max contour error {:.6f} mm at {:.3f} s, corner miss {:.6f} mm "
      "(move {}), {} limit violations",
      machining_time_s, path_length_mm, max_contour_error_mm, contour_error_time_s, max_corner_miss_mm,
      corner_miss_segment, limit_violations);
  if (limit_violations > 0) {
    s += fmt::format(" (first at {:.3f} s: axis {} derivative {} = {:.6g}, limit {:.6g})",
                     first_violation.time_s, kAxisLetters[static_cast<std::size_t>(first_violation.axis)],
                     first_violation.derivative, first_violation.value, first_violation.limit);
  }
  for (int i = 0; i < kAxisCount; ++i) {
    const AxisStats& a = axes[static_cast<std::size_t>(i)];
    if (a.max_velocity == 0 && a.max_acceleration == 0) continue;
    s += fmt::format("\n  {}: v {:.6g}  a {:.6g}  j {:.6g}", kAxisLetters[static_cast<std::size_t>(i)],
                     a.max_velocity, a.max_acceleration, a.max_jerk);
  }
  return s;
}

TraceChecker::TraceChecker(const canon::Program& program, const plan::MachineLimits& limits, double period_s,
                           double relative_tolerance)
    : program_(&program), limits_(limits), period_s_(period_s), tolerance_(relative_tolerance) {
  past_.fill(program.start());
}

TraceChecker::TraceChecker(const plan::MachineLimits& limits, double period_s, double relative_tolerance)
    : program_(nullptr), limits_(limits), period_s_(period_s), tolerance_(relative_tolerance) {}

// Distance from p to a box that holds move `id` (a lower bound of the distance to the move).
double TraceChecker::box_distance(canon::SegmentId id, const Pose& p) const {
  const Pose a = program_->start_of(id), b = program_->end(id);
  double grow = 0;
  if (program_->move(id).kind == canon::MoveKind::RigidTap) return 0;  // its line has no box
  if (program_->move(id).kind == canon::MoveKind::Arc) {
    const canon::ArcGeometry& g = program_->arc(id);
    const int b0 = canon::plane_base(g.plane);
    double r2 = 0, e2 = 0;
    for (int k = 0; k < 3; ++k) {
      r2 += (a[b0 + k] - g.center[k]) * (a[b0 + k] - g.center[k]);
      e2 += (b[b0 + k] - g.center[k]) * (b[b0 + k] - g.center[k]);
    }
    // The whole circle (or spiral, between its two radii) fits in the end points' box grown by
    // its largest diameter.
    grow = 2 * std::sqrt(std::max(r2, e2));
  }
  double s = 0;
  for (int i : kLinear) {
    const double lo = std::min(a[i], b[i]) - grow, hi = std::max(a[i], b[i]) + grow;
    const double d = p[i] < lo ? lo - p[i] : (p[i] > hi ? p[i] - hi : 0.0);
    s += d * d;
  }
  return std::sqrt(s);
}

double TraceChecker::distance_to_move(canon::SegmentId id, const Pose& p) const {
  const Pose start = program_->start_of(id), end = program_->end(id);
  const canon::MoveKind kind = program_->move(id).kind;
  if (kind == canon::MoveKind::Arc) return arc_distance(program_->arc(id), start, end, p);
  // A rigid tap follows the spindle beyond the bottom and above its start while the spindle
  // reverses (as in LinuxCNC): its contour error is the distance from its line.
  if (kind == canon::MoveKind::RigidTap) return line_distance(start, end, p);
  return segment_distance(start, end, p);
}

void TraceChecker::check_limits(const Pose& x) {
  const double t = period_s_, t2 = t * t, t3 = t2 * t;
  for (int i = 0; i < kAxisCount; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double x1 = past_[0][i], x2 = past_[1][i], x3 = past_[2][i];
    const double v = std::fabs(x[i] - x1) / t;
    const double a = std::fabs(x[i] - 2 * x1 + x2) / t2;
    const double j = jerk_unknown_ ? 0.0 : std::fabs(x[i] - 3 * x1 + 3 * x2 - x3) / t3;
    AxisStats& st = report_.axes[k];
    st.max_velocity = std::max(st.max_velocity, v);
    st.max_acceleration = std::max(st.max_acceleration, a);
    st.max_jerk = std::max(st.max_jerk, j);
    const plan::AxisLimits& l = limits_[i];
    const double values[3] = {v, a, j};
    const double caps[3] = {l.max_velocity, l.max_acceleration * accel_scale_, l.max_jerk * accel_scale_};
    for (int d = 0; d < 3; ++d) {
      if (caps[d] <= 0 || values[d] <= caps[d] * (1 + tolerance_)) continue;
      if (report_.limit_violations++ == 0) {
        report_.first_violation = {static_cast<double>(report_.samples) * t, i, d + 1, values[d], caps[d]};
      }
    }
  }
  jerk_unknown_ = false;
}

// The end points of the moves from the one before `first` to `last` are near the block the
// sample lies on: each keeps its distance to the nearest chord between two samples so far (the
// chord to this sample counts for those of the blocks it crossed too). Once the trace is on a
// block starting two moves after one, that move's end point is passed: its distance counts.
void TraceChecker::track_corners(const Pose& position, canon::SegmentId first, canon::SegmentId last) {
  const canon::SegmentId n = program_->size();
  const canon::SegmentId held = program_->first_held_move();  // end(id) needs id ≥ held
  const canon::SegmentId lo = std::max<canon::SegmentId>(first > 0 ? first - 1 : 0, held);
  const canon::SegmentId hi = std::min<canon::SegmentId>(last, n - 1);
  if (lo > hi) return;
  if (!corners_.empty() && lo < corner_base_) corners_.clear();  // a new run of the program
  if (corners_.empty()) corner_base_ = lo;
  while (corner_base_ + corners_.size() <= hi) corners_.push_back(1e300);
  Pose second{};
  for (int i : kLinear) second[i] = position[i] - 2 * past_[0][i] + past_[1][i];
  const double bulge = linear_distance(second, Pose{});
  for (std::size_t k = 0; k < corners_.size(); ++k) {
    if (corner_base_ + k < held) continue;  // released: it keeps what it had (and counts below)
    const Pose v = program_->end(corner_base_ + k);
    double d = segment_distance(past_[0], position, v);
    // The chord cuts inside a curved path by about |Δ²x|/8: where that could matter, the path
    // between the samples is taken as the arc through this sample and the two before it.
    if (d - bulge < corners_[k]) d = std::min(d, arc_distance(past_[1], past_[0], position, v));
    corners_[k] = std::min(corners_[k], d);
  }
  while (!corners_.empty() && corner_base_ < lo) {
    if (corners_.front() < 1e300 && corners_.front() > report_.max_corner_miss_mm) {
      report_.max_corner_miss_mm = corners_.front();
      report_.corner_miss_segment = corner_base_;
    }
    corners_.pop_front();
    ++corner_base_;
  }
}

void TraceChecker::add(const Pose& position, canon::SegmentId first, canon::SegmentId last) {
  ++report_.samples;
  report_.machining_time_s = static_cast<double>(report_.samples) * period_s_;
  check_limits(position);
  report_.path_length_mm += linear_distance(position, past_[0]);
  if (program_ != nullptr && program_->size() > 0) {
    const canon::SegmentId n = program_->size();
    // (In a stream's window the moves before the first held one are gone, and start_of(id) needs
    // the end of the move before id.)
    const canon::SegmentId held = program_->first_held_move();
    const canon::SegmentId lo =
        std::max<canon::SegmentId>(first > 0 ? first - 1 : 0, held > 0 ? held + 1 : 0);
    const canon::SegmentId hi = std::min<canon::SegmentId>(last + 1, n - 1);
    // Merged blocks stand for hundreds of moves: start with the move that was nearest last time
    // and skip those whose bounding box is already farther than the best distance.
    double best = 1e300;
    if (nearest_ >= lo && nearest_ <= hi) best = distance_to_move(nearest_, position);
    for (canon::SegmentId id = lo; id <= hi && id < n; ++id) {
      if (id == nearest_ || box_distance(id, position) >= best) continue;
      const double d = distance_to_move(id, position);
      if (d < best) {
        best = d;
        nearest_ = id;
      }
    }
    if (best < 1e300 && best > report_.max_contour_error_mm) {
      report_.max_contour_error_mm = best;
      report_.contour_error_time_s = report_.machining_time_s;
    }
    track_corners(position, first, last);
  }
  past_[2] = past_[1];
  past_[1] = past_[0];
  past_[0] = position;
}

}  // namespace opencnc::analysis
