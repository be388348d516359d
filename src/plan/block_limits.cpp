// SPDX-License-Identifier: GPL-3.0-or-later
// Per-axis limits → one speed cap and one acceleration budget along s, per block shape.
//
// With s(t) the path parameter, an axis moves as x(t) = g(s(t)), so
//   ẋ = g'·v,   ẍ = g'·a + g''·v²,   x⃛ = g'·j + 3·g''·v·a + g'''·v³.
// A block's (cap, accel) pair is chosen so that |ẋ|, |ẍ|, |x⃛| stay within the axis limits for
// every v ≤ cap, |a| ≤ accel, and |j| ≤ 2·accel/T (the jerk of a moving average of length T over
// a profile whose acceleration stays within ±accel).
#include "block_limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "opencnc/traj/path_eval.hpp"

namespace opencnc::plan::detail {

using traj::BlockKind;
using traj::MotionBlock;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kJerkCapShare = 0.5;  ///< part of the continuous jerk share v³·|g'''| may use

bool limited_jerk(const LimitParams& p, int i) {
  return p.filter_s > 0 && p.machine[i].max_jerk > 0;
}

RawLimits line_limits(const MotionBlock& b, double v_max, const LimitParams& p) {
  RawLimits r{v_max, kInf};
  for (int i = 0; i < kAxisCount; ++i) {
    const double d = std::fabs(b.lin[i]);
    if (d < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    r.cap = std::min(r.cap, l.max_velocity / d);
    r.accel = std::min(r.accel, l.max_acceleration / d);
    if (limited_jerk(p, i))
      r.accel = std::min(r.accel, (1 - p.step_share) * l.max_jerk * p.filter_s / (2 * d));
  }
  return r;
}

/// Largest a ≥ 0 with k·√(a² + q²) + λ·a ≤ A (given k·q ≤ A), in the cancellation-free form.
double arc_accel(double k, double lambda, double q, double A) {
  const double slack = A * A - k * k * q * q;
  if (slack <= 0) return 0;
  return slack / (A * lambda + k * std::sqrt(lambda * lambda * q * q + slack));
}

/// Largest a in [0, a_hi] with f(a) ≤ budget for an increasing f (bisection; planning time only).
template <typename F>
double largest_within(F f, double budget, double a_hi) {
  if (f(a_hi) <= budget) return a_hi;
  double lo = 0, hi = a_hi;
  if (f(lo) > budget) return 0;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) <= budget ? lo : hi) = mid;
  }
  return lo;
}

// Circle or helix: g' = ω·(cos·w + sin·u) + λ, g'' = ω²·(cos·u − sin·w), g''' = −ω²·g'_circle.
// Per axis, with k = |ω|·√(u² + w²): |g'| ≤ k + |λ|, the in-plane acceleration is at most
// k·√(a² + v⁴ω²) and the in-plane jerk k·√((j + v³ω²)² + (3·v·a·ω)²).
//
// Spiral: with a = 1 + ρθ the circle's terms are a times the arc's, and the radius change adds
//   g'  += ω·ρ·(sin·w − cos·u),   g'' += 2·ω²·ρ·(cos·w + sin·u),   g''' += 3·ω³·ρ·(cos·u − sin·w),
// each at most k·|ρ| (times ω, ω²) per axis. So with A_max = max(1, 1 + ρθ_end):
//   |ẍ| ≤ k·A_max·√(a² + v⁴ω²) + (λ + k|ρ|)·|a| + 2·k|ρ|·v²|ω|,
//   |x⃛| ≤ k·A_max·√((j + v³ω²)² + (3vaω)²) + λ·j + k|ρ|·(j + 6·v·a·|ω| + 3·v³ω²),
// the arc's bounds (ρ = 0) plus terms of the order of ρ (0.001 for the arcs LinuxCNC accepts
// with large radii). With ρ = 0 (an arc block) every added term is exactly zero: arcs use this
// too.
RawLimits arc_or_spiral_limits(const MotionBlock& b, double v_max, const LimitParams& p) {
  const double om = std::fabs(b.omega), rho = std::fabs(b.spiral);
  const double grow_max = std::max(1.0, 1.0 + b.spiral * b.omega * b.length);
  double ks[kAxisCount];
  double cap = v_max;
  for (int i = 0; i < kAxisCount; ++i) {
    const double k = ks[i] = om * std::sqrt(b.u[i] * b.u[i] + b.w[i] * b.w[i]), lam = std::fabs(b.lin[i]);
    if (k + lam < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    cap = std::min(cap, l.max_velocity / (k * std::hypot(grow_max, rho) + lam));
    if (k > 0)
      cap = std::min(cap, std::sqrt(p.normal_share * l.max_acceleration / (om * k * (grow_max + 2 * rho))));
    if (k > 0 && limited_jerk(p, i)) {
      cap = std::min(cap, std::cbrt(kJerkCapShare * (1 - p.step_share) * l.max_jerk /
                                    (om * om * k * (grow_max + 3 * rho))));
    }
  }
  double accel = kInf;
  const double q = cap * cap * om;
  for (int i = 0; i < kAxisCount; ++i) {
    const double k = ks[i], lam = std::fabs(b.lin[i]);
    if (k + lam < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    const double budget = l.max_acceleration - 2 * k * rho * q;
    double a = budget > 0 ? arc_accel(k * grow_max, lam + k * rho, q, budget) : 0.0;
    if (limited_jerk(p, i)) {
      const double T = p.filter_s, v = cap;
      const auto jerk = [&](double acc) {
        const double j = 2 * acc / T;
        return k * grow_max * std::hypot(j + v * v * v * om * om, 3 * v * acc * om) + lam * j +
               k * rho * (j + 6 * v * acc * om + 3 * v * v * v * om * om);
      };
      a = largest_within(jerk, (1 - p.step_share) * l.max_jerk, a);
    }
    accel = std::min(accel, a);
  }
  return {cap, accel};
}

// Cubic Bézier at t = s/L: per-axis bounds of g', g'', g''' from the control polygon (the
// derivative of a Bézier is a Bézier of the differences, within their convex hull).
RawLimits bezier_limits(const MotionBlock& b, double v_max, const LimitParams& p) {
  const double L = b.length;
  double cap = v_max;
  double d1[kAxisCount], d2[kAxisCount], d3[kAxisCount];
  for (int i = 0; i < kAxisCount; ++i) {
    const double p0 = b.base[i], p1 = b.u[i], p2 = b.w[i], p3 = b.lin[i];
    d1[i] = 3 * std::max({std::fabs(p1 - p0), std::fabs(p2 - p1), std::fabs(p3 - p2)}) / L;
    d2[i] = 6 * std::max(std::fabs(p2 - 2 * p1 + p0), std::fabs(p3 - 2 * p2 + p1)) / (L * L);
    d3[i] = 6 * std::fabs(p3 - 3 * p2 + 3 * p1 - p0) / (L * L * L);
    if (d1[i] + d2[i] < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    if (d1[i] > 0) cap = std::min(cap, l.max_velocity / d1[i]);
    if (d2[i] > 0) cap = std::min(cap, std::sqrt(p.normal_share * l.max_acceleration / d2[i]));
    if (d3[i] > 0 && limited_jerk(p, i)) {
      cap = std::min(cap, std::cbrt(kJerkCapShare * (1 - p.step_share) * l.max_jerk / d3[i]));
    }
  }
  double accel = kInf;
  for (int i = 0; i < kAxisCount; ++i) {
    if (d1[i] + d2[i] < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    if (d1[i] <= 0) continue;
    accel = std::min(accel, (l.max_acceleration - cap * cap * d2[i]) / d1[i]);
    if (limited_jerk(p, i)) {
      const double budget = (1 - p.step_share) * l.max_jerk - cap * cap * cap * d3[i];
      accel = std::min(accel, budget / (2 * d1[i] / p.filter_s + 3 * cap * d2[i]));
    }
  }
  return {cap, std::max(accel, 0.0)};
}

}  // namespace

RawLimits block_limits(const MotionBlock& b, double v_commanded_max, const LimitParams& p) noexcept {
  switch (b.kind) {
    case BlockKind::Line:
      return line_limits(b, v_commanded_max, p);
    case BlockKind::Arc:
    case BlockKind::Spiral:
      return arc_or_spiral_limits(b, v_commanded_max, p);
    case BlockKind::Bezier:
      return bezier_limits(b, v_commanded_max, p);
    case BlockKind::Marker:
      break;
  }
  return {kInf, kInf};
}

Pose curvature_step(const MotionBlock& prev, const MotionBlock& next) noexcept {
  const Pose c1 = traj::curvature_at(prev, prev.length), c2 = traj::curvature_at(next, 0.0);
  Pose step;
  for (int i = 0; i < kAxisCount; ++i) {
    const double d = std::fabs(c2[i] - c1[i]);
    step[i] = d > 1e-12 ? d : 0.0;
  }
  return step;
}

}  // namespace opencnc::plan::detail
