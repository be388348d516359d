// SPDX-License-Identifier: GPL-3.0-or-later
// NURBS evaluation (de Boor) and chord splitting (Bezier pieces from the blossom of each span,
// then de Casteljau halving until each piece's control points hug its chord).
#include "opencnc/canon/nurbs.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::canon {

namespace {

// A control point in homogeneous coordinates (x·w, y·w, w).
struct H {
  double x = 0, y = 0, w = 1;
};
H lerp(const H& a, const H& b, double t) noexcept {
  return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.w + t * (b.w - a.w)};
}
H homogeneous(const NurbsPoint& p) noexcept { return {p.x * p.weight, p.y * p.weight, p.weight}; }
CurvePoint project(const H& h, double u) noexcept { return {h.x / h.w, h.y / h.w, u}; }

double distance_to_segment(const CurvePoint& p, const CurvePoint& a, const CurvePoint& b) noexcept {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

// The blossom (polar form) of the curve on span s at the parameters t[0..p-1]: de Boor's
// algorithm with a different parameter on each level. With all t equal it is the curve point.
H blossom(const std::vector<H>& cp, const std::vector<double>& knots, std::size_t p, std::size_t s,
          const double* t, std::vector<H>& d) {
  for (std::size_t j = 0; j <= p; ++j) d[j] = cp[j + s - p];
  for (std::size_t r = 1; r <= p; ++r) {
    for (std::size_t j = p; j >= r; --j) {
      const double lo = knots[j + s - p], hi = knots[j + 1 + s - r];
      d[j] = lerp(d[j - 1], d[j], (t[r - 1] - lo) / (hi - lo));
    }
  }
  return d[p];
}

// The Bezier control points of span s (knots[s] < knots[s+1]): b_i is the blossom at
// (a, ..., a, b, ..., b) with i copies of b. O(p^3) per span, independent of the curve's length.
void bezier_of_span(const std::vector<H>& cp, const std::vector<double>& knots, std::size_t p, std::size_t s,
                    std::vector<H>& piece, std::vector<H>& work) {
  std::vector<double> t(p);
  for (std::size_t i = 0; i <= p; ++i) {
    for (std::size_t k = 0; k < p; ++k) t[k] = k < p - i ? knots[s] : knots[s + 1];
    piece[i] = blossom(cp, knots, p, s, t.data(), work);
  }
}

// Halves a rational Bezier piece on [u0, u1] until its control points are within `tol` of
// its chord, appending the piece ends.
void flatten(const std::vector<H>& piece, double u0, double u1, double tol, int depth, std::vector<CurvePoint>& out) {
  const CurvePoint a = project(piece.front(), u0), b = project(piece.back(), u1);
  bool flat = depth >= 48;   // far below any machine's resolution; stops runaway on NaN input
  if (!flat) {
    flat = true;
    for (std::size_t i = 1; i + 1 < piece.size() && flat; ++i)
      flat = distance_to_segment(project(piece[i], 0), a, b) <= tol;
  }
  if (flat) {
    out.push_back(b);
    return;
  }
  // de Casteljau at t = 1/2: the left edge of the triangle is the first half, the right edge
  // (read backwards) the second.
  std::vector<H> tri = piece, left(piece.size()), right(piece.size());
  const std::size_t n = piece.size() - 1;
  left[0] = tri[0];
  right[n] = tri[n];
  for (std::size_t r = 1; r <= n; ++r) {
    for (std::size_t i = 0; i + r <= n; ++i) tri[i] = lerp(tri[i], tri[i + 1], 0.5);
    left[r] = tri[0];
    right[n - r] = tri[n - r];
  }
  const double um = 0.5 * (u0 + u1);
  flatten(left, u0, um, tol, depth + 1, out);
  flatten(right, um, u1, tol, depth + 1, out);
}

std::vector<CurvePoint> control_polygon(std::span<const NurbsPoint> points) {
  std::vector<CurvePoint> out;
  for (std::size_t i = 1; i < points.size(); ++i) out.push_back({points[i].x, points[i].y, static_cast<double>(i)});
  return out;
}

}  // namespace

std::vector<double> nurbs_knots(std::size_t count, int order) {
  const std::size_t k = static_cast<std::size_t>(order);
  std::vector<double> knots;
  knots.reserve(count + k);
  for (std::size_t i = 0; i < count + k; ++i) {
    if (i < k) knots.push_back(0);
    else if (i < count) knots.push_back(static_cast<double>(i - k + 1));
    else knots.push_back(static_cast<double>(count - k + 1));
  }
  return knots;
}

CurvePoint nurbs_point(std::span<const NurbsPoint> points, int order, double u) {
  const std::vector<double> knots = nurbs_knots(points.size(), order);
  const std::size_t p = static_cast<std::size_t>(order - 1);
  u = std::clamp(u, knots.front(), knots.back());
  // The span: knots[s] <= u < knots[s+1], the last span for u at the end.
  std::size_t s = static_cast<std::size_t>(std::upper_bound(knots.begin(), knots.end(), u) - knots.begin()) - 1;
  s = std::min(s, points.size() - 1);
  std::vector<H> d(p + 1);
  for (std::size_t j = 0; j <= p; ++j) d[j] = homogeneous(points[j + s - p]);
  for (std::size_t r = 1; r <= p; ++r) {
    for (std::size_t j = p; j >= r; --j) {
      const double lo = knots[j + s - p], hi = knots[j + 1 + s - r];
      d[j] = lerp(d[j - 1], d[j], (u - lo) / (hi - lo));
    }
  }
  return project(d[p], u);
}

std::vector<CurvePoint> tessellate_nurbs(std::span<const NurbsPoint> points, int order, double tolerance) {
  if (points.size() < 2) return {};
  const bool positive = std::all_of(points.begin(), points.end(), [](const NurbsPoint& q) { return q.weight > 0; });
  // Above order 64 the pieces cost O(order^3) each (LinuxCNC's own evaluation is exponential
  // in the order): the control polygon then.
  if (!positive || order < 2 || order > 64 || static_cast<std::size_t>(order) > points.size())
    return control_polygon(points);
  const std::size_t p = static_cast<std::size_t>(order - 1);
  const std::vector<double> knots = nurbs_knots(points.size(), order);
  std::vector<H> cp;
  cp.reserve(points.size());
  for (const NurbsPoint& q : points) cp.push_back(homogeneous(q));
  const double last = knots.back();
  std::vector<CurvePoint> out;
  std::vector<H> piece(p + 1), work(p + 1);
  for (std::size_t s = p; s + 1 < knots.size() - p; ++s) {   // the spans [s, s+1] of positive length
    if (!(knots[s] < knots[s + 1])) continue;
    bezier_of_span(cp, knots, p, s, piece, work);
    flatten(piece, knots[s], knots[s + 1], tolerance, 0, out);
  }
  out.back() = {points.back().x, points.back().y, last};
  return out;
}

}  // namespace opencnc::canon
