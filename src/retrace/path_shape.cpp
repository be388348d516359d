// SPDX-License-Identifier: GPL-3.0-or-later
// Lines and arcs of the path index: construction from the program, points, boxes, nearest points.
#include "path_shape.hpp"

#include <algorithm>
#include <cmath>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/core/minimise.hpp"

namespace opencnc::recovery::detail {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Squared distance in the metric: XY ignores Z.
double dist2(const Vec3& a, const Vec3& b, Metric m) noexcept {
  const double dx = a[0] - b[0], dy = a[1] - b[1];
  const double dz = m == Metric::Xyz ? a[2] - b[2] : 0.0;
  return dx * dx + dy * dy + dz * dz;
}

/// The first θ of the sweep (from 0 toward `sweep`) at the angle `phi`, or −1 if it lies outside.
double first_angle(double phi, double sweep) noexcept {
  if (sweep >= 0) {
    const double t = phi < 0 ? phi + 2 * kPi : phi;
    return t <= sweep ? t / sweep : -1;
  }
  const double t = phi > 0 ? phi - 2 * kPi : phi;
  return t >= sweep ? t / sweep : -1;
}

/// Numerical minimum of the squared distance over t ∈ [0, 1]: samples every π/32 of the sweep
/// (at least 16), then golden-section search around the best sample. For curves the closed form
/// does not cover (a helix in 3D, an arc of a vertical plane seen from above).
Closest numeric(const Shape& s, const ArcShape& arc, const Vec3& q, Metric m) noexcept {
  const int n = std::max(16, static_cast<int>(std::ceil(std::fabs(arc.sweep) / (kPi / 32))));
  int best = 0;
  double best_d2 = 1e300;
  for (int i = 0; i <= n; ++i) {
    const double d2 = dist2(point_at(s, &arc, static_cast<double>(i) / n), q, m);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  const auto f = [&](double t) { return dist2(point_at(s, &arc, t), q, m); };
  const Minimum g = golden_section(f, static_cast<double>(std::max(0, best - 1)) / n,
                                   static_cast<double>(std::min(n, best + 1)) / n, 80, 1e-15);
  return best_d2 <= g.f ? Closest{static_cast<double>(best) / n, best_d2} : Closest{g.x, g.f};
}

}  // namespace

bool make_arc_shape(const canon::Program& p, std::size_t move, ArcShape& out) {
  const canon::ArcGeometry& g = p.arc(move);
  if (canon::plane_base(g.plane) != 0) return false;
  const Vec3 s = take3(p.start_of(move)), e = take3(p.end(move));
  const Vec3& n = g.normal;
  const Vec3& c0 = g.center;
  Vec3 rs = s - c0;
  rs = rs - dot(rs, n) * n;
  const double r0 = std::sqrt(dot(rs, rs));
  if (!(r0 >= 1e-9)) return false;
  const Vec3 u1 = (1.0 / r0) * rs, u2 = cross(n, u1);
  Vec3 re = e - c0;
  re = re - dot(re, n) * n;
  const double ex = dot(re, u1), ey = dot(re, u2), r_end = std::hypot(ex, ey);
  // Rounded coordinates give slightly different radii at the two ends: the centre goes onto the
  // bisector of the end points so that the circle passes through both (as the planner runs it).
  double cx = 0, cy = 0;
  const double dx = ex - r0, dy = ey, dd = dx * dx + dy * dy;
  if (dd > 1e-24) {
    const double k = 0.5 * (r_end * r_end - r0 * r0) / dd;
    cx = k * dx;
    cy = k * dy;
  }
  out.c = c0 + (cx * u1 + cy * u2);
  const Vec3 rs2 = rs - (cx * u1 + cy * u2);
  out.r = std::sqrt(dot(rs2, rs2));
  out.c = out.c + dot(s - c0, n) * n;  // the centre in the start's plane
  out.e1 = (1.0 / out.r) * rs2;
  out.e2 = cross(n, out.e1);
  const Vec3 re2 = re - (cx * u1 + cy * u2);
  out.sweep = canon::arc_sweep(std::atan2(dot(re2, out.e2), dot(re2, out.e1)), g.turns == 0 ? 1 : g.turns);
  const Vec3 circle_end =
      out.c + ((out.r * std::cos(out.sweep)) * out.e1 + (out.r * std::sin(out.sweep)) * out.e2);
  out.rest = e - circle_end;
  constexpr double kFlat = 1e-12;
  out.circle_xyz =
      std::fabs(out.rest[0]) < kFlat && std::fabs(out.rest[1]) < kFlat && std::fabs(out.rest[2]) < kFlat;
  out.circle_xy =
      std::fabs(n[2]) > 1 - 1e-12 && std::fabs(out.rest[0]) < kFlat && std::fabs(out.rest[1]) < kFlat;
  return true;
}

Vec3 point_at(const Shape& s, const ArcShape* arc, double t) noexcept {
  if (arc == nullptr) return s.a + t * (s.b - s.a);
  if (t >= 1) return s.b;
  if (t <= 0) return s.a;
  const double th = t * arc->sweep;
  return (arc->c + ((arc->r * std::cos(th)) * arc->e1 + (arc->r * std::sin(th)) * arc->e2)) + t * arc->rest;
}

Box bounds(const Shape& s, const ArcShape* arc) noexcept {
  Box b;
  b.add(s.a);
  b.add(s.b);
  if (arc == nullptr) return b;
  // The circle's part: its ends and, along each axis, the two extreme points of the circle
  // where the sweep passes them (θ = atan2(e2ᵢ, e1ᵢ) and that + π); the rise t·rest then
  // widens the box by its range.
  const auto circle = [&](double th) {
    return arc->c + ((arc->r * std::cos(th)) * arc->e1 + (arc->r * std::sin(th)) * arc->e2);
  };
  Box c;
  c.add(circle(0));
  c.add(circle(arc->sweep));
  const bool whole = std::fabs(arc->sweep) >= 2 * kPi;
  for (int i = 0; i < 3; ++i) {
    if (arc->e1[i] == 0 && arc->e2[i] == 0) continue;
    const double th = std::atan2(arc->e2[i], arc->e1[i]);
    for (const double phi : {th, th > 0 ? th - kPi : th + kPi}) {
      if (whole || first_angle(phi, arc->sweep) >= 0) c.add(circle(phi));
    }
  }
  for (int i = 0; i < 3; ++i) {
    b.lo[i] = std::min(b.lo[i], c.lo[i] + std::min(0.0, arc->rest[i]));
    b.hi[i] = std::max(b.hi[i], c.hi[i] + std::max(0.0, arc->rest[i]));
  }
  return b;
}

double length(const Shape& s, const ArcShape* arc) noexcept {
  if (arc == nullptr) return norm(s.b - s.a);
  return std::hypot(arc->r * arc->sweep, std::sqrt(dot(arc->rest, arc->rest)));
}

Closest closest(const Shape& s, const ArcShape* arc, const Vec3& q, Metric m) noexcept {
  if (arc == nullptr) {
    const Vec3 d = s.b - s.a;
    const double l2 = d[0] * d[0] + d[1] * d[1] + (m == Metric::Xyz ? d[2] * d[2] : 0.0);
    double t = 0;
    if (l2 > 0) {
      const Vec3 w = q - s.a;
      t = (w[0] * d[0] + w[1] * d[1] + (m == Metric::Xyz ? w[2] * d[2] : 0.0)) / l2;
      t = std::clamp(t, 0.0, 1.0);
    }
    return {t, dist2(point_at(s, nullptr, t), q, m)};
  }
  if (!(m == Metric::Xy ? arc->circle_xy : arc->circle_xyz)) return numeric(s, *arc, q, m);
  // A circular arc in the metric's view: the nearest point of the circle lies at the query's
  // angle about the centre; if the sweep does not reach it, the nearer end is the nearest.
  Vec3 w = q - arc->c;
  if (m == Metric::Xy) w[2] = 0;
  Closest best{0, dist2(s.a, q, m)};
  const double d_end = dist2(s.b, q, m);
  if (d_end < best.d2) best = {1, d_end};
  const double x = dot(w, arc->e1), y = dot(w, arc->e2);
  if (x != 0 || y != 0) {
    const double t = first_angle(std::atan2(y, x), arc->sweep);
    if (t >= 0) {
      const double d2 = dist2(point_at(s, arc, t), q, m);
      if (d2 < best.d2) best = {t, d2};
    }
  }
  return best;
}

}  // namespace opencnc::recovery::detail
