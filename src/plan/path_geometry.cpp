// SPDX-License-Identifier: GPL-3.0-or-later
// Planner geometry: lines and arcs in nine axes, trimming, tolerance-bounded corner blends.
#include "path_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/core/minimise.hpp"
#include "opencnc/core/vec3.hpp"
#include "opencnc/traj/path_eval.hpp"
#include "vec.hpp"

namespace opencnc::plan::detail {

using traj::BlockKind;

namespace {

constexpr double kPi = std::numbers::pi;

}  // namespace

bool make_line(const Pose& a, const Pose& b, MotionBlock& out) noexcept {
  const Pose d = b - a;
  const double len = norm(d);
  if (!(len >= kMinLength)) return false;
  out.kind = BlockKind::Line;
  out.base = a;
  out.lin = (1.0 / len) * d;
  out.u = Pose{};
  out.w = Pose{};
  out.omega = 0;
  out.length = len;
  return true;
}

namespace {

// LinuxCNC's tolerance on an arc's end radius (its interpreter's, for inch programs: the larger
// of its two, so that nothing an interpreter accepted is refused here): within the absolute
// tolerance, or within the relative one up to 100 times the absolute one.
constexpr double kSpiralAbsMm = 2 * 0.001 * 1.41421356237309504880 * 25.4;
constexpr double kSpiralRelative = 0.001;
/// Radii that differ by less than this (relative) are the same circle up to rounding.
constexpr double kSameRadius = 1e-9;

/// ∫ f over [0, span] by 8-point Gauss-Legendre on `pieces` equal parts (f smooth on each).
template <typename F>
double gauss_legendre(F f, double span, int pieces) {
  static constexpr double kNode[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                      0.9602898564975363};
  static constexpr double kWeight[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                        0.1012285362903763};
  const double step = span / pieces, half = 0.5 * step;
  double sum = 0;
  for (int k = 0; k < pieces; ++k) {
    const double mid = (k + 0.5) * step;
    for (int q = 0; q < 4; ++q) sum += kWeight[q] * (f(mid - half * kNode[q]) + f(mid + half * kNode[q]));
  }
  return half * sum;
}

/// Quarter turns in a sweep (at least one): the pieces of a spiral's quadrature.
int quarter_turns(double sweep) noexcept {
  return std::max(1, static_cast<int>(std::ceil(std::fabs(sweep) / (0.5 * kPi))));
}

/// Length of a spiral block over θ ∈ [0, sweep]: |dp/dθ|² = r0²·((1 + ρθ)² + ρ²) + h² (h: the
/// linear part per radian), the root of a quadratic in θ, smooth and positive.
double spiral_length(double r0, double rho, double h, double sweep) noexcept {
  const auto speed = [&](double th) {
    const double a = 1.0 + rho * th;
    return std::sqrt(r0 * r0 * (a * a + rho * rho) + h * h);
  };
  return std::fabs(gauss_legendre(speed, sweep, quarter_turns(sweep)));
}

}  // namespace

bool make_arc(const Pose& start, const Pose& end, const canon::ArcGeometry& arc, MotionBlock& out,
              std::string& error) {
  const int b0 = canon::plane_base(arc.plane);
  const Vec3& n = arc.normal;
  const Vec3& c = arc.center;
  const Vec3 s3 = take3(start, b0), e3 = take3(end, b0);
  Vec3 rs = s3 - c;
  rs = rs - dot(rs, n) * n;
  const double r = std::sqrt(dot(rs, rs));
  {
    // An arc whose circle is smaller than a nanometre at both ends (which the interpreter, as
    // LinuxCNC's, accepts) is its chord to within that nanometre: run it as a line rather than
    // refuse at run time what the check passed.
    Vec3 re = e3 - c;
    re = re - dot(re, n) * n;
    if (r < kPointArcMm && std::sqrt(dot(re, re)) < kPointArcMm) return make_line(start, end, out);
  }
  if (!(r >= 1e-9)) {
    error = "the arc's start point lies on its centre (radius zero)";
    return false;
  }
  const Vec3 e1 = (1.0 / r) * rs, e2 = cross(n, e1);
  Vec3 re = e3 - c;
  re = re - dot(re, n) * n;
  const double ex = dot(re, e1), ey = dot(re, e2);
  const double r_end = std::hypot(ex, ey);
  const double off = std::fabs(r_end - r);
  if (!(r_end >= 1e-9) || off > 100 * kSpiralAbsMm ||
      (off > kSpiralAbsMm && off > kSpiralRelative * std::max(r, r_end))) {
    error = fmt::format(
        "the arc's end point is {:.4f} mm off its circle (radius {:.4f} mm at the start, "
        "{:.4f} mm at the end), beyond LinuxCNC's tolerance",
        off, r, r_end);
    return false;
  }
  if (off > kSameRadius * std::max(1.0, r)) return make_spiral(start, end, arc, r, r_end, out);
  // Radii equal to rounding: move the centre onto the perpendicular bisector of the two end
  // points, so that the circle passes through both to the last bit.
  double cx = 0, cy = 0;
  const double dx = ex - r, dy = ey, dd = dx * dx + dy * dy;
  if (dd > 1e-24) {
    const double k = 0.5 * (r_end * r_end - r * r) / dd;
    cx = k * dx;
    cy = k * dy;
  }
  const Vec3 c2 = c + (cx * e1 + cy * e2);
  const Vec3 rs2 = s3 - c2;
  const double r2 = std::sqrt(dot(rs2, rs2));
  const Vec3 f1 = (1.0 / r2) * rs2, f2 = cross(n, f1);
  const Vec3 re2 = re - (cx * e1 + cy * e2);
  const double phi = std::atan2(dot(re2, f2), dot(re2, f1));
  const double sweep = canon::arc_sweep(phi, arc.turns == 0 ? 1 : arc.turns);

  Pose U{}, W{};
  put3(U, b0, -r2 * f1);  // toward the centre
  put3(W, b0, r2 * f2);   // counterclockwise tangent, length r
  const Pose circle = std::sin(sweep) * W + (1.0 - std::cos(sweep)) * U;
  const Pose rest = end - start - circle;  // helix rise and every other axis, moved linearly
  const double len = std::hypot(r2 * sweep, norm(rest));
  out.kind = BlockKind::Arc;
  out.base = start;
  out.u = U;
  out.w = W;
  out.length = len;
  out.omega = sweep / len;
  out.spiral = 0;
  out.lin = (1.0 / len) * rest;
  return true;
}

// An arc whose end lies off its start circle, as LinuxCNC's planner runs it: the radius goes
// linearly with the angle from the start radius to the end radius about the programmed centre,
// and the axial rise and the other axes linearly with it too. The path parameter s is the
// spiral's length, θ = ω·s, so the speed along the curve follows the radius within their ratio.
bool make_spiral(const Pose& start, const Pose& end, const canon::ArcGeometry& arc, double r0, double r1,
                 MotionBlock& out) {
  const int b0 = canon::plane_base(arc.plane);
  const Vec3& n = arc.normal;
  const Vec3& c = arc.center;
  Vec3 rs = take3(start, b0) - c;
  rs = rs - dot(rs, n) * n;
  const Vec3 e1 = (1.0 / r0) * rs, e2 = cross(n, e1);
  Vec3 re = take3(end, b0) - c;
  re = re - dot(re, n) * n;
  const double phi = std::atan2(dot(re, e2), dot(re, e1));
  const double sweep = canon::arc_sweep(phi, arc.turns == 0 ? 1 : arc.turns);
  const double rho = (r1 - r0) / (r0 * sweep);
  Pose U{}, W{};
  put3(U, b0, -r0 * e1);
  put3(W, b0, r0 * e2);
  const double grow = rho * sweep, sn = std::sin(sweep), cs = std::cos(sweep);
  const Pose turn = sn * W + (1.0 - cs) * U + grow * (sn * W - cs * U);
  const Pose rest = end - start - turn;
  const double len = spiral_length(r0, rho, norm(rest) / std::fabs(sweep), sweep);
  out.kind = BlockKind::Spiral;
  out.base = start;
  out.u = U;
  out.w = W;
  out.length = len;
  out.omega = sweep / len;
  out.spiral = rho;
  out.lin = (1.0 / len) * rest;
  return true;
}

namespace {

/// Length of a spiral block's path in the axis triple from `first` (its tangent restricted to
/// the triple, over the block's s).
double spiral_triple_length(const MotionBlock& b, int first) noexcept {
  const auto speed = [&](double s) {
    const Pose t = traj::tangent_at(b, s);
    return std::sqrt(t[first] * t[first] + t[first + 1] * t[first + 1] + t[first + 2] * t[first + 2]);
  };
  return gauss_legendre(speed, b.length, quarter_turns(b.omega * b.length));
}

}  // namespace

double feed_length_ratio(const Pose& start, const Pose& end, const MotionBlock& b) noexcept {
  const auto part = [](const Pose& v, int first) {
    return std::sqrt(v[first] * v[first] + v[first + 1] * v[first + 1] + v[first + 2] * v[first + 2]);
  };
  double feed_len = 0;
  if (b.kind == BlockKind::Spiral) {
    const int first = (std::fabs(b.u[6]) + std::fabs(b.u[7]) + std::fabs(b.u[8]) > 0) ? 6 : 0;
    feed_len = spiral_triple_length(b, first);
  } else if (b.kind == BlockKind::Arc) {
    // The circle's plane holds XYZ or UVW; the helix length in that triple carries the feed.
    const int first = (std::fabs(b.u[6]) + std::fabs(b.u[7]) + std::fabs(b.u[8]) > 0) ? 6 : 0;
    const double circle = std::fabs(b.omega) * norm(b.u) * b.length;
    feed_len = std::hypot(circle, part(b.lin, first) * b.length);
  } else {
    const Pose d = end - start;
    feed_len = part(d, 0);
    if (feed_len < 1e-12) feed_len = part(d, 6);
    if (feed_len < 1e-12) feed_len = part(d, 3);
  }
  return feed_len > 1e-12 ? b.length / feed_len : 1.0;
}

namespace {

// Splits a cubic Bézier at t (de Casteljau): the head keeps [0, t], the tail [t, 1]. The path
// parameter keeps its scale (head length L·t, tail L·(1 − t)), so s runs on unchanged.
void split_bezier(const MotionBlock& b, double t, MotionBlock* head, MotionBlock* tail) {
  const auto lerp = [t](const Pose& a, const Pose& c) { return a + t * (c - a); };
  const Pose p01 = lerp(b.base, b.u), p12 = lerp(b.u, b.w), p23 = lerp(b.w, b.lin);
  const Pose p012 = lerp(p01, p12), p123 = lerp(p12, p23), mid = lerp(p012, p123);
  if (head != nullptr) {
    head->u = p01;
    head->w = p012;
    head->lin = mid;
    head->length = b.length * t;
  }
  if (tail != nullptr) {
    tail->base = mid;
    tail->u = p123;
    tail->w = p23;
    tail->length = b.length * (1 - t);
  }
}

// The same for a quintic (de Casteljau on six points).
void split_quintic(const MotionBlock& b, double t, MotionBlock* head, MotionBlock* tail) {
  Pose q[6] = {b.base, b.u, b.w, b.lin, b.p4, b.p5};
  Pose left[6], right[6];
  for (int level = 0; level < 6; ++level) {
    left[level] = q[0];
    right[5 - level] = q[5 - level];
    for (int k = 0; k + level < 5; ++k) q[k] = q[k] + t * (q[k + 1] - q[k]);
  }
  if (head != nullptr) {
    head->base = left[0], head->u = left[1], head->w = left[2], head->lin = left[3], head->p4 = left[4];
    head->p5 = left[5];
    head->length = b.length * t;
  }
  if (tail != nullptr) {
    tail->base = right[0], tail->u = right[1], tail->w = right[2], tail->lin = right[3], tail->p4 = right[4];
    tail->p5 = right[5];
    tail->length = b.length * (1 - t);
  }
}

}  // namespace

void trim_start(MotionBlock& b, double d) noexcept {
  if (d <= 0) return;
  b.segment_offset += d;
  if (b.kind == BlockKind::Bezier) {
    split_bezier(b, d / b.length, nullptr, &b);
    return;
  }
  if (b.kind == BlockKind::Quintic) {
    split_quintic(b, d / b.length, nullptr, &b);
    return;
  }
  const Pose p = traj::position_at(b, d);
  if (b.kind == BlockKind::Arc || b.kind == BlockKind::Spiral) {
    // The frame turns with the start point; a spiral's radius there is (1 + ρθ) times the old
    // one, and the rest of it grows by the same ρ per radian of the old radius.
    const double phi = b.omega * d, c = std::cos(phi), s = std::sin(phi);
    const double scale = b.kind == BlockKind::Spiral ? 1.0 + b.spiral * phi : 1.0;
    const Pose u = scale * (c * b.u - s * b.w), w = scale * (s * b.u + c * b.w);
    b.u = u;
    b.w = w;
    if (b.kind == BlockKind::Spiral) b.spiral /= scale;
  }
  b.base = p;
  b.length -= d;
}

void trim_end(MotionBlock& b, double d) noexcept {
  if (d <= 0) return;
  if (b.kind == BlockKind::Bezier) {
    split_bezier(b, (b.length - d) / b.length, &b, nullptr);
    return;
  }
  if (b.kind == BlockKind::Quintic) {
    split_quintic(b, (b.length - d) / b.length, &b, nullptr);
    return;
  }
  b.length -= d;
}

void rebase(MotionBlock& b, const Pose& p) noexcept {
  if (b.kind == BlockKind::Line) {
    const Pose end = end_point(b);
    const Pose d = end - p;
    const double len = norm(d);
    b.base = p;
    if (len > 0) {
      b.lin = (1.0 / len) * d;
      b.length = len;
    }
    return;
  }
  b.base = p;
}

Pose end_point(const MotionBlock& b) noexcept {
  return traj::position_at(b, b.length);
}

Pose end_tangent(const MotionBlock& b) noexcept {
  const Pose t = traj::tangent_at(b, b.length);
  return (1.0 / norm(t)) * t;
}

Pose start_tangent(const MotionBlock& b) noexcept {
  const Pose t = traj::tangent_at(b, 0.0);
  return (1.0 / norm(t)) * t;
}

namespace {

/// Smallest distance from p to block b for s within a quarter turn of `s0`: Newton's method on
/// the derivative of the squared distance, golden section where that is not convex.
double nearest_on(const MotionBlock& b, const Pose& p, double s0) noexcept {
  const double reach = 0.25 * kPi / std::fabs(b.omega);
  double s = s0;
  for (int i = 0; i < 8; ++i) {
    const Pose r = p - traj::position_at(b, s);
    const Pose t = traj::tangent_at(b, s);
    const double g1 = -dot(r, t), g2 = dot(t, t) - dot(r, traj::curvature_at(b, s));
    if (!(g2 > 0)) break;
    const double next = std::clamp(s - g1 / g2, std::max(0.0, s0 - reach), std::min(b.length, s0 + reach));
    if (std::fabs(next - s) < 1e-13 * (1 + b.length)) {
      return std::min(norm(p - traj::position_at(b, next)), norm(p - traj::position_at(b, s0)));
    }
    s = next;
  }
  const auto d = [&](double x) { return norm(p - traj::position_at(b, x)); };
  const Minimum m = golden_section(d, std::max(0.0, s0 - reach), std::min(b.length, s0 + reach), 60, 1e-12);
  return std::min(m.f, d(s0));
}

}  // namespace

double distance_to(const MotionBlock& b, const Pose& p) noexcept {
  if (b.kind == BlockKind::Line) {
    const double t = std::clamp(dot(p - b.base, b.lin), 0.0, b.length);
    return norm(p - (b.base + t * b.lin));
  }
  if (b.kind == BlockKind::Arc) {
    // The angle of p about the axis picks the parameter (exact for a planar arc); on a helix the
    // nearest point is near there, and a golden-section search around it finds it.
    const double r = norm(b.u);
    const Pose centre = b.base + b.u;
    const Pose q = p - centre;
    const double qa = -dot(q, b.u) / r, qb = dot(q, b.w) / r;
    double phi = std::atan2(qb, qa);  // angle from the start direction, counterclockwise
    const double sweep = b.omega * b.length;
    if (sweep < 0) phi = -phi;
    if (phi < 0) phi += 2 * kPi;
    const double span = std::fabs(sweep);
    double best = std::min(norm(p - b.base), norm(p - end_point(b)));
    const bool helix = norm(b.lin) > 1e-12;
    for (double a = phi; a <= span; a += 2 * kPi) {
      const double s = a / std::fabs(b.omega);
      const double same_angle = norm(p - traj::position_at(b, s));
      best = std::min(best, helix && same_angle > 1e-9 ? nearest_on(b, p, s) : same_angle);
    }
    if (helix && best > 1e-9) best = std::min({best, nearest_on(b, p, 0.0), nearest_on(b, p, b.length)});
    return best;
  }
  if (b.kind == BlockKind::Spiral) {
    // The angle of p about the centre gives a parameter near the nearest point on each turn;
    // the search around it finds the point (the radius changes slowly with the angle).
    const double r = norm(b.u);
    const Pose q = p - (b.base + b.u);
    double phi = std::atan2(dot(q, b.w) / r, -dot(q, b.u) / r);
    const double sweep = b.omega * b.length;
    if (sweep < 0) phi = -phi;
    if (phi < 0) phi += 2 * kPi;
    double best = std::min(norm(p - b.base), norm(p - end_point(b)));
    for (double a = phi; a <= std::fabs(sweep); a += 2 * kPi)
      best = std::min(best, nearest_on(b, p, a / std::fabs(b.omega)));
    // Searches from the ends only where p's angle lies outside the sweep: inside, the search from
    // that angle finds the nearest point (every result is the distance to a point of the curve, so
    // skipping a search can only overstate the distance, never understate it).
    if (phi <= std::fabs(sweep)) return best;
    return std::min({best, nearest_on(b, p, 0.0), nearest_on(b, p, b.length)});
  }
  // Bézier: sampled (only used for short blend curves).
  double best = 1e300;
  for (int k = 0; k <= 64; ++k) best = std::min(best, norm(p - traj::position_at(b, b.length * k / 64.0)));
  return best;
}

namespace {

/// Radius for which a circle in the plane of unit vectors `t` and `n` can be run at the needed
/// speed: v²·√(t_i² + n_i²)/R ≤ share·A_i on every axis, i.e. R = v²/share · max_i √(t_i² + n_i²)/A_i
/// (one square root of the largest square).
double needed_radius(const Pose& t, const Pose& n, const BlendNeed& need) {
  double worst = 0;
  for (int i = 0; i < kAxisCount; ++i) {
    const double a = need.accel[static_cast<std::size_t>(i)];
    if (a > 0) worst = std::max(worst, (t[i] * t[i] + n[i] * n[i]) / (a * a));
  }
  return need.speed * need.speed * std::sqrt(worst) / need.share;
}

bool line_line_blend(const MotionBlock& in, double avail_in, const MotionBlock& out, double avail_out,
                     double tolerance, const BlendNeed& need, const CornerTurn& turn, Blend& result) {
  // Circular fillet tangent to both lines: tangent length d, radius R = d / tan(θ/2). Its middle
  // is nearest to the corner, R·(1/cos(θ/2) − 1) from it (and R·(1 − cos(θ/2)) from the lines):
  // that distance ≤ tolerance, as LinuxCNC sizes its blend arcs, so that the path passes within
  // the tolerance of the corner too (a hairpin is not cut off at its moves' middles). And no
  // larger than the speed needs. From s = sin(θ/2) and c = cos(θ/2): tan(θ/2) = s/c and
  // 1 − c = s²/(1 + c), without cancellation at small angles, so d ≤ tolerance·(1 + c)/s.
  const double theta = turn.angle, s = turn.half_sine, c2 = std::sqrt(1.0 - s * s);
  const double t2 = s / c2;
  const Pose& ta = turn.in;
  Pose n = turn.out - ta;
  n = n - dot(n, ta) * ta;
  n = (1.0 / norm(n)) * n;
  double d = std::min({avail_in, avail_out, needed_radius(ta, n, need) * t2});
  if (tolerance > 0) d = std::min(d, tolerance * (1.0 + c2) / s);
  if (!(d >= kMinLength)) return false;
  const double radius = d / t2;
  MotionBlock& c = result.curve;  // the caller sets identity, class and feed
  c.line = in.line;
  c.context = in.context;
  c.kind = BlockKind::Arc;
  c.base = end_point(in) - d * ta;
  c.w = radius * ta;
  c.u = radius * n;
  c.lin = Pose{};
  c.length = radius * theta;
  c.omega = 1.0 / radius;
  result.trim_in = d;
  result.trim_out = d;
  (void)out;
  return true;
}

/// Cubic Bézier from the point `d` before the corner on `in` to the point `d` after it on
/// `out`, tangent to both, with arms that make it close to a circular fillet.
void bezier_at(const MotionBlock& in, const MotionBlock& out, double d, MotionBlock& c) {
  const Pose p0 = traj::position_at(in, in.length - d);
  const Pose p3 = traj::position_at(out, d);
  // The arms along dp/ds of the pieces (not only its direction): the velocity stays continuous
  // where |dp/ds| is not exactly 1 (a spiral, a fitted run of short moves).
  const Pose da = traj::tangent_at(in, in.length - d), db = traj::tangent_at(out, d);
  const double theta = angle_between((1.0 / norm(da)) * da, (1.0 / norm(db)) * db);
  const double cq = std::cos(0.25 * theta);
  const double h = norm(p3 - p0) / (3.0 * cq * cq);
  c.line = in.line;  // the caller sets identity, class and feed
  c.context = in.context;
  c.kind = BlockKind::Bezier;
  c.base = p0;
  c.u = p0 + h * da;
  c.w = p3 - h * db;
  c.lin = p3;
  c.length = 3.0 * h;
  c.omega = 0;
}

/// Largest distance from the Bézier to the two programmed blocks (sampled, plus the most the
/// curve can move between samples); once it passes `stop_above` the rest is not sampled.
double bezier_deviation(const MotionBlock& c, const MotionBlock& in, const MotionBlock& out,
                        double stop_above) {
  constexpr int kSamples = 32;
  const double arm = std::max({norm(c.u - c.base), norm(c.w - c.u), norm(c.lin - c.w)});
  const double margin = 3.0 * arm / (2.0 * kSamples);
  double worst = 0;
  // From the middle outwards, the block on the sample's side first: the largest distance is
  // usually found first, and a sample nearer than it to one block needs no other distance.
  for (int m = 0; m < kSamples - 1 && worst + margin <= stop_above; ++m) {
    const int k = kSamples / 2 + (m % 2 == 0 ? m / 2 : -(m + 1) / 2);
    const Pose p = traj::position_at(c, c.length * k / kSamples);
    const MotionBlock& near = 2 * k <= kSamples ? in : out;
    const MotionBlock& far = 2 * k <= kSamples ? out : in;
    const double d_near = distance_to(near, p);
    if (d_near > worst) worst = std::max(worst, std::min(d_near, distance_to(far, p)));
  }
  return worst + margin;
}

bool bezier_blend(const MotionBlock& in, double avail_in, const MotionBlock& out, double avail_out,
                  double tolerance, const BlendNeed& need, double theta, const Pose& ta, const Pose& tb,
                  Blend& result) {
  // A cubic's curvature peaks above that of the circular fillet it imitates: allow it twice the
  // fillet's tangent length before the speed no longer needs more.
  Pose n = tb - ta;
  n = n - dot(n, ta) * ta;
  n = (1.0 / norm(n)) * n;
  const double d_need =
      theta > kTangentAngle ? 2.0 * needed_radius(ta, n, need) * std::tan(0.5 * theta) : avail_in;
  const double d_max = std::min({avail_in, avail_out, d_need});
  if (!(d_max >= kMinLength)) return false;
  const auto ok = [&](double d) {
    bezier_at(in, out, d, result.curve);
    if (result.curve.length < kMinLength) return false;
    return tolerance <= 0 || (point_to_curve(result.curve, end_point(in)) <= tolerance &&
                              bezier_deviation(result.curve, in, out, tolerance) <= tolerance);
  };
  double d = d_max;
  if (!ok(d)) {  // to 10⁻⁴ of d_max: a blend 0.01 % shorter costs nothing measurable
    double lo = 0, hi = d_max;
    for (int i = 0; i < 40 && hi - lo > 1e-4 * d_max; ++i) {
      const double mid = 0.5 * (lo + hi);
      (ok(mid) ? lo : hi) = mid;
    }
    d = lo;
    if (!(d >= kMinLength) || !ok(d)) return false;
  }
  result.trim_in = d;
  result.trim_out = d;
  return true;
}

}  // namespace

JoinPoint join_at(const MotionBlock& b, double s) noexcept {
  return {traj::position_at(b, s), traj::tangent_at(b, s), traj::curvature_at(b, s)};
}

namespace {

/// Control points of the G2 quintic for parameter length L.
void g2_points(const JoinPoint& a, const JoinPoint& b, double L, MotionBlock& c) {
  const double h = L / 5, k = L * L / 20;
  c.base = a.p;
  c.u = a.p + h * a.d1;
  c.w = 2.0 * c.u - a.p + k * a.d2;
  c.p5 = b.p;
  c.p4 = b.p - h * b.d1;
  c.lin = 2.0 * c.p4 - b.p + k * b.d2;
  c.length = L;
}

/// Arc length of a quintic block (8-point Gauss-Legendre: the speed of a blend is smooth) and
/// its smallest speed |dB/dt| among the nodes relative to L (a cusp makes it vanish).
double quintic_arc_length(const MotionBlock& c, double& slowest) {
  static constexpr double kNode[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                      0.9602898564975363};
  static constexpr double kWeight[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                        0.1012285362903763};
  double sum = 0;
  slowest = 1e300;
  for (int q = 0; q < 4; ++q) {
    for (int side = -1; side <= 1; side += 2) {
      const double t = 0.5 + side * 0.5 * kNode[q];
      const double speed = norm(traj::tangent_at(c, t * c.length));  // |dB/dt| / L
      slowest = std::min(slowest, speed);
      sum += kWeight[q] * speed;
    }
  }
  return 0.5 * sum * c.length;
}

}  // namespace

bool make_g2_curve(const JoinPoint& a, const JoinPoint& b, MotionBlock& out) noexcept {
  const double chord = norm(b.p - a.p);
  if (!(chord >= kMinLength)) return false;
  out.kind = BlockKind::Quintic;
  out.omega = 0;
  out.spiral = 0;
  double L = chord;
  for (int it = 0; it < 12; ++it) {
    g2_points(a, b, L, out);
    double slowest = 0;
    const double next = quintic_arc_length(out, slowest);
    if (!(slowest > 0.05) || !(next > 0)) return false;  // (nearly) a cusp: no useful curve
    // Any L keeps the curve G2; its own length only makes |dp/ds| about 1 (the feed).
    if (std::fabs(next - L) <= 1e-6 * L) {
      L = next;
      break;
    }
    L = next;
  }
  g2_points(a, b, L, out);
  return std::isfinite(L) && L >= kMinLength;
}

double point_to_curve(const MotionBlock& c, const Pose& v) noexcept {
  // The nearest of 16 samples, then a golden-section search between its neighbours: the distance
  // to a point of the curve, so never below the true distance.
  constexpr int kSamples = 16;
  const auto dist = [&](double t) { return norm(traj::position_at(c, c.length * t) - v); };
  int best_k = 0;
  double best = dist(0.0);
  for (int k = 1; k <= kSamples; ++k) {
    const double d = dist(static_cast<double>(k) / kSamples);
    if (d < best) {
      best = d;
      best_k = k;
    }
  }
  constexpr double kGolden = 0.6180339887498949;
  double a = std::max(0, best_k - 1) / static_cast<double>(kSamples);
  double b = std::min(kSamples, best_k + 1) / static_cast<double>(kSamples);
  double x1 = b - kGolden * (b - a), x2 = a + kGolden * (b - a), f1 = dist(x1), f2 = dist(x2);
  for (int it = 0; it < 24; ++it) {
    if (f1 < f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - kGolden * (b - a);
      f1 = dist(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + kGolden * (b - a);
      f2 = dist(x2);
    }
  }
  return std::min({best, f1, f2});
}

bool blend_within(const MotionBlock& c, const MotionBlock& in, const MotionBlock& out,
                  double tolerance) noexcept {
  return point_to_curve(c, end_point(in)) <= tolerance &&
         curve_within(
             c, [&](const Pose& p) { return std::min(distance_to(in, p), distance_to(out, p)); }, tolerance);
}

double speed_scale_step(const MotionBlock& in, const MotionBlock& out) noexcept {
  return std::fabs(norm(traj::tangent_at(in, in.length)) - norm(traj::tangent_at(out, 0.0)));
}

bool same_speed_scale(const MotionBlock& in, const MotionBlock& out) noexcept {
  return speed_scale_step(in, out) <= 1e-9;
}

CornerTurn corner_turn(const MotionBlock& in, const MotionBlock& out) noexcept {
  CornerTurn t;
  t.in = end_tangent(in);
  t.out = start_tangent(out);
  t.half_sine = std::min(0.5 * norm(t.out - t.in), 1.0);  // as in angle_between()
  t.angle = 2.0 * std::asin(t.half_sine);
  return t;
}

bool blend_corner(const MotionBlock& in, double avail_in, const MotionBlock& out, double avail_out,
                  const CornerTurn& turn, double tolerance, const BlendNeed& need, Blend& result) {
  const Pose& ta = turn.in;
  const Pose& tb = turn.out;
  const double theta = turn.angle;
  if (theta >= kReversalAngle) return false;
  if (theta <= kTangentAngle) {  // tangent, but |dp/ds| differs: a transition between the two
    if (same_speed_scale(in, out)) return false;
    return bezier_blend(in, avail_in, out, avail_out, tolerance, need, theta, ta, tb, result);
  }
  if (in.kind == BlockKind::Line && out.kind == BlockKind::Line) {
    return line_line_blend(in, avail_in, out, avail_out, tolerance, need, turn, result);
  }
  return bezier_blend(in, avail_in, out, avail_out, tolerance, need, theta, ta, tb, result);
}

}  // namespace opencnc::plan::detail
