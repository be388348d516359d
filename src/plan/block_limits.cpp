// SPDX-License-Identifier: GPL-3.0-or-later
// Per-axis limits → one speed cap, one acceleration budget and one jerk budget along s, per block
// shape.
//
// With s(t) the path parameter, an axis moves as x(t) = g(s(t)), so
//   ẋ = g'·v,   ẍ = g'·a + g''·v²,   x⃛ = g'·j + 3·g''·v·a + g'''·v³.
// A block's (cap, accel, jerk) triple is chosen so that |ẋ|, |ẍ|, |x⃛| stay within the axis
// limits for every v ≤ cap, |a| ≤ accel and |j| ≤ jerk. With jerk limits the geometric term
// g'''·v³ may take at most half of J at the cap (kJerkCapShare; a Bézier block's cap rises from
// there where its pieces leave the budget, bezier_limits), the acceleration budget is the
// largest that leaves a jerk budget of at least accel/T (so the moving average of length T can
// always turn the acceleration round), and the jerk budget is what is left at that budget.
#include "block_limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "opencnc/traj/path_eval.hpp"

namespace opencnc::plan::detail {

using traj::BlockKind;
using traj::MotionBlock;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;
constexpr double kJerkCapShare = 0.5;  ///< part of J the geometric jerk v³·|g'''| may use at the cap
                                       ///< (Bézier blocks: the reference their cap rises from)
constexpr double kTradedBudget = 0.25;  ///< Bézier: share of the budget a cap below the feed may give up
constexpr double kLowBudget = 0.1;     ///< Bézier: of the axes' acceleration, a budget that limits

bool limited_jerk(const LimitParams& p, int i) {
  return p.filter_s > 0 && p.machine[i].max_jerk > 0;
}

RawLimits line_limits(const MotionBlock& b, double v_max, const LimitParams& p, double jerk_scale) {
  RawLimits r{v_max, kInf, kInf};
  for (int i = 0; i < kAxisCount; ++i) {
    const double d = std::fabs(b.lin[i]);
    if (d < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    r.cap = std::min(r.cap, l.max_velocity / d);
    r.accel = std::min(r.accel, l.max_acceleration / d);
    if (limited_jerk(p, i)) r.jerk = std::min(r.jerk, jerk_scale * l.max_jerk / d);
  }
  if (r.jerk < kInf) r.accel = std::min(r.accel, r.jerk * p.filter_s);
  return r;
}

/// Largest a ≥ 0 with k·√(a² + q²) + λ·a ≤ A (given k·q ≤ A), in the cancellation-free form.
double arc_accel(double k, double lambda, double q, double A) {
  const double slack = A * A - k * k * q * q;
  if (slack <= 0) return 0;
  return slack / (A * lambda + k * std::sqrt(lambda * lambda * q * q + slack));
}

/// Largest x in [0, x_hi] with f(x) ≤ budget for an increasing f (bisection; planning time only).
template <typename F>
double largest_within(F f, double budget, double x_hi) {
  if (f(x_hi) <= budget) return x_hi;
  double lo = 0, hi = x_hi;
  if (f(lo) > budget) return 0;
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) <= budget ? lo : hi) = mid;
  }
  return lo;
}

/// Smallest and largest of R·cos(φ − ψ) for φ in [lo, hi]: the ends and the extrema inside.
void cos_range(double R, double psi, double lo, double hi, double& mn, double& mx) {
  mn = std::min(R * std::cos(lo - psi), R * std::cos(hi - psi));
  mx = std::max(R * std::cos(lo - psi), R * std::cos(hi - psi));
  if (hi - lo >= 2 * kPi) {
    mn = -R;
    mx = R;
    return;
  }
  for (double m = std::ceil((lo - psi) / kPi); psi + m * kPi <= hi; m += 1) {
    if (std::fmod(std::fabs(m), 2.0) < 0.5) {
      mx = R;
    } else {
      mn = -R;
    }
  }
}

/// Limits of a circular arc over the angle it sweeps (no jerk limit). The whole-circle bounds
/// (arc_or_spiral_limits) take each axis's largest |g'| and |g''| on the full circle; a corner
/// fillet sweeps a few degrees, over which a diagonal pair of axes keeps |g'_i| near 0.7 instead
/// of 1, so the fillet may run as fast as the lines it joins (LinuxCNC's blend arcs do). Per axis,
/// with φ = ω·s,  g'_i = ω·(w_i·cos φ + u_i·sin φ) + λ_i  and  g''_i = ω²·(u_i·cos φ − w_i·sin φ):
/// shifted R·cos(φ − ψ), whose extrema over the sweep are exact (cos_range). The budget is
/// (A_i − v²·G2)/G1 with G1, G2 bounds of |g'_i|, |g''_i| on each of 24 pieces of the sweep (the
/// values at its ends and the next derivative's bound: |g''_i| ≤ D2, |g'''_i| ≤ |ω|³·r_i). The cap
/// is the highest at which that budget still reaches the whole-circle budget `a_min` (a higher
/// cap with less budget would trade braking for speed).
/// {cap −1}: no better than the whole-circle limits.
RawLimits arc_sweep_limits(const MotionBlock& b, double v_max, const LimitParams& p, double cap_lo,
                           double a_min) {
  constexpr int kPieces = 24;
  const double om = b.omega, aom = std::fabs(om), L = b.length;
  const double lo = std::min(0.0, om * L), hi = std::max(0.0, om * L), dphi = (hi - lo) / kPieces;
  double cap = v_max;
  double d1[kAxisCount]{}, d2[kAxisCount]{}, d3[kAxisCount]{};
  for (int i = 0; i < kAxisCount; ++i) {
    const double r = std::hypot(b.u[i], b.w[i]), lam = b.lin[i];
    if (aom * r + std::fabs(lam) < 1e-15) continue;
    double mn = 0, mx = 0;
    if (r > 0) cos_range(aom * r, std::atan2(om * b.u[i], om * b.w[i]), lo, hi, mn, mx);
    d1[i] = std::max(std::fabs(mn + lam), std::fabs(mx + lam));
    mn = mx = 0;
    if (r > 0) cos_range(om * om * r, std::atan2(-b.w[i], b.u[i]), lo, hi, mn, mx);
    d2[i] = std::max(std::fabs(mn), std::fabs(mx));
    d3[i] = aom * om * om * r;
    const AxisLimits& l = p.machine[i];
    if (d1[i] > 0) cap = std::min(cap, l.max_velocity / d1[i]);
    if (d2[i] > 0) cap = std::min(cap, std::sqrt(p.normal_share * l.max_acceleration / d2[i]));
  }
  if (cap <= cap_lo) return {-1, 0, 0};
  // Per piece G1 ≥ |g'_i| and G2 ≥ |g''_i| on it. The budget at v is min (A_i − v²·G2)/G1, so the
  // cap at which it still reaches a_min is v² = min (A_i − a_min·G1)/G2, in closed form.
  const double ds = L / kPieces, cd = std::cos(dphi), sd = std::sin(dphi);
  double G1[kAxisCount][kPieces], G2[kAxisCount][kPieces];
  double v2 = cap * cap;
  for (int i = 0; i < kAxisCount; ++i) {
    if (d1[i] <= 0) continue;
    double c = std::cos(lo), sn = std::sin(lo);  // the sample angle, turned by dphi each step
    double g1_prev = std::fabs(om * (b.w[i] * c + b.u[i] * sn) + b.lin[i]);
    double g2_prev = std::fabs(om * om * (b.u[i] * c - b.w[i] * sn));
    const double A = p.machine[i].max_acceleration;
    for (int q = 0; q < kPieces; ++q) {
      const double c_next = c * cd - sn * sd;
      sn = sn * cd + c * sd;
      c = c_next;
      const double g1 = std::fabs(om * (b.w[i] * c + b.u[i] * sn) + b.lin[i]);
      const double g2 = std::fabs(om * om * (b.u[i] * c - b.w[i] * sn));
      G1[i][q] = std::min(d1[i], 0.5 * (g1_prev + g1 + d2[i] * ds));
      G2[i][q] = std::min(d2[i], 0.5 * (g2_prev + g2 + d3[i] * ds));
      g1_prev = g1;
      g2_prev = g2;
      const double room = A - a_min * G1[i][q];
      if (room < 0) return {-1, 0, 0};
      if (G2[i][q] > 0) v2 = std::min(v2, room / G2[i][q]);
    }
  }
  cap = std::sqrt(v2);
  if (cap <= cap_lo) return {-1, 0, 0};
  double a = kInf;
  for (int i = 0; i < kAxisCount; ++i) {
    if (d1[i] <= 0) continue;
    for (int q = 0; q < kPieces; ++q) {
      if (G1[i][q] > 0) a = std::min(a, (p.machine[i].max_acceleration - v2 * G2[i][q]) / G1[i][q]);
    }
  }
  return {cap, std::max(a, 0.0), kInf};
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
RawLimits arc_or_spiral_limits(const MotionBlock& b, double v_max, const LimitParams& p, double jerk_scale) {
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
      cap = std::min(
          cap, std::cbrt(kJerkCapShare * jerk_scale * l.max_jerk / (om * om * k * (grow_max + 3 * rho))));
    }
  }
  RawLimits r{cap, kInf, kInf};
  const double q = cap * cap * om;
  const double T = p.filter_s, v = cap;
  for (int i = 0; i < kAxisCount; ++i) {
    const double k = ks[i], lam = std::fabs(b.lin[i]);
    if (k + lam < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    const double budget = l.max_acceleration - 2 * k * rho * q;
    double a = budget > 0 ? arc_accel(k * grow_max, lam + k * rho, q, budget) : 0.0;
    if (limited_jerk(p, i)) {
      const auto jerk = [&](double acc, double j) {
        return k * grow_max * std::hypot(j + v * v * v * om * om, 3 * v * acc * om) + lam * j +
               k * rho * (j + 6 * v * acc * om + 3 * v * v * v * om * om);
      };
      const double J = jerk_scale * l.max_jerk;
      a = largest_within([&](double acc) { return jerk(acc, acc / T); }, J, a);
      const double j_hi = J / (k * grow_max + lam + k * rho);  // the j terms alone reach J there
      r.jerk = std::min(r.jerk, largest_within([&](double j) { return jerk(a, j); }, J, j_hi));
    }
    r.accel = std::min(r.accel, a);
  }
  if (b.spiral == 0 && r.jerk == kInf && p.filter_s <= 0 && r.cap < v_max) {
    const RawLimits sweep = arc_sweep_limits(b, v_max, p, r.cap, r.accel);
    if (sweep.cap > r.cap) return sweep;
  }
  return r;
}

// Cubic or quintic Bézier at t = s/L. Per axis the caps use the largest |g'|, |g''| on the block
// (D1, D2): v·D1 ≤ V, v²·D2 ≤ α·A. The budgets use g', g'', g''' where they occur together: on
// each of kIntervals pieces of t, bounds G1, G2, G3 from the values at its ends and the next
// derivative's bound (a function whose slope is at most M stays within (f_a + f_b + M·Δs)/2
// between a and b), and |ẍ| ≤ G1·|a| + G2·v², |x⃛| ≤ G1·|j| + 3·G2·v·|a| + G3·v³ there: VPOp's
// axis jerk constraint (Beudaert, Lavernhe, Tournier 2012) held piece by piece. Along a curve
// the axis that carries the curvature (or its change, g''') is rarely the one that carries the
// tangent, so the budget at a cap is far above what the block's separate maxima would leave.
//
// The jerk cap: the reference is the geometric jerk v³·D3 at kJerkCapShare of J (D3 the largest
// |g'''| on the block) and the budget the pieces leave at that speed. From there the cap rises to
// the highest speed at which every piece still leaves that same budget (with j = a/T, the least
// the moving average needs): where the pieces with a large |g'''| have a small |g'| and |g''| on
// the same axis the geometric jerk takes far more than half of J there, at no cost to the budget.
double bernstein(const double* c, int n, double t);

constexpr int kIntervals = 24;  ///< pieces of a Bézier block on which g', g'', g''' are bounded

/// Per axis bounds of |g'|, |g''| and (with `jerk`) |g'''| on each piece of a Bézier block.
struct BezierPieces {
  double g1[kAxisCount][kIntervals], g2[kAxisCount][kIntervals], g3[kAxisCount][kIntervals];
};

void bezier_pieces(const MotionBlock& b, const double* d1, const double* d2, const double* d3, bool jerk,
                   BezierPieces& out) {
  const double L = b.length, ds = L / kIntervals;
  const int n = b.kind == BlockKind::Quintic ? 5 : 3;
  for (int i = 0; i < kAxisCount; ++i) {
    if (d1[i] <= 0) continue;
    double c[6], e1[5], e2[4], e3[3];
    for (int k = 0; k <= n; ++k) c[k] = traj::detail::quintic_point(b, k)[i];
    for (int k = 0; k < n; ++k) e1[k] = n * (c[k + 1] - c[k]);
    for (int k = 0; k < n - 1; ++k) e2[k] = (n - 1) * (e1[k + 1] - e1[k]);
    for (int k = 0; k < n - 2; ++k) e3[k] = (n - 2) * (e2[k + 1] - e2[k]);
    double d4 = 0;  // the largest |g''''| (the cubic's g''' is constant)
    for (int k = 0; k + 1 < n - 2; ++k) d4 = std::max(d4, std::fabs((n - 3) * (e3[k + 1] - e3[k])));
    d4 /= L * L * L * L;
    double v1 = 0, v2 = 0, v3 = 0;
    for (int q = 0; q <= kIntervals; ++q) {
      const double t = static_cast<double>(q) / kIntervals;
      const double w1 = std::fabs(bernstein(e1, n - 1, t)) / L;
      const double w2 = std::fabs(bernstein(e2, n - 2, t)) / (L * L);
      const double w3 = jerk ? std::fabs(bernstein(e3, n - 3, t)) / (L * L * L) : 0.0;
      if (q > 0) {
        out.g1[i][q - 1] = std::min(d1[i], 0.5 * (v1 + w1 + d2[i] * ds));
        out.g2[i][q - 1] = std::min(d2[i], 0.5 * (v2 + w2 + d3[i] * ds));
        out.g3[i][q - 1] = std::min(d3[i], 0.5 * (v3 + w3 + d4 * ds));
      }
      v1 = w1;
      v2 = w2;
      v3 = w3;
    }
  }
}

/// Largest v ≥ 0 with G3·v³ + B·v ≤ R (G3, B ≥ 0, R > 0): Newton's method from above on the convex
/// cubic, so every iterate stays at or above the root; the budgets are computed again at the cap
/// chosen, so being above it by rounding costs nothing but that rounding.
double cubic_speed(double G3, double B, double R) {
  if (G3 <= 0) return B > 0 ? R / B : kInf;
  double v = std::cbrt(R / G3);
  if (B > 0) v = std::min(v, R / B);
  for (int it = 0; it < 8; ++it) {
    const double f = G3 * v * v * v + B * v - R;
    if (f <= 0) break;
    v -= f / (3 * G3 * v * v + B);
  }
  return v;
}

RawLimits bezier_limits(const MotionBlock& b, double v_max, const LimitParams& p, double jerk_scale) {
  double d1[kAxisCount], d2[kAxisCount], d3[kAxisCount];
  derivative_bounds(b, d1, d2, d3);
  double cap = v_max, cap_jerk = kInf, low_budget = kInf;
  bool jerk = false;
  for (int i = 0; i < kAxisCount; ++i) {
    if (d1[i] + d2[i] < 1e-15) continue;
    const AxisLimits& l = p.machine[i];
    if (d1[i] > 0) cap = std::min(cap, l.max_velocity / d1[i]);
    if (d2[i] > 0) cap = std::min(cap, std::sqrt(p.normal_share * l.max_acceleration / d2[i]));
    if (d1[i] > 0 && limited_jerk(p, i)) {
      jerk = true;
      low_budget = std::min(low_budget, kLowBudget * l.max_acceleration);
    }
    if (d3[i] > 0 && limited_jerk(p, i))
      cap_jerk = std::min(cap_jerk, std::cbrt(kJerkCapShare * jerk_scale * l.max_jerk / d3[i]));
  }
  BezierPieces pc;
  bezier_pieces(b, d1, d2, d3, jerk, pc);
  const double T = p.filter_s;
  // The acceleration budget the pieces leave at speed v with j = a/T; with `whole` also the one
  // with the whole block's largest |g'''| on every piece. (A quotient is taken only where it
  // lowers the budget.)
  const auto accel_at = [&](double v, double* a_whole) {
    double a = kInf, aw = kInf;
    for (int i = 0; i < kAxisCount; ++i) {
      if (d1[i] <= 0) continue;
      const AxisLimits& l = p.machine[i];
      const double J = jerk_scale * l.max_jerk;
      for (int q = 0; q < kIntervals; ++q) {
        const double G1 = pc.g1[i][q], G2 = pc.g2[i][q];
        if (G1 <= 0) continue;
        const double by_accel = (l.max_acceleration - v * v * G2) / G1;
        a = std::min(a, by_accel);
        aw = std::min(aw, by_accel);
        if (!limited_jerk(p, i)) continue;
        const double den = G1 / T + 3 * v * G2;
        const double v3 = v * v * v;
        if (J - v3 * pc.g3[i][q] < a * den) a = (J - v3 * pc.g3[i][q]) / den;
        if (a_whole && J - v3 * d3[i] < aw * den) aw = (J - v3 * d3[i]) / den;
      }
    }
    if (a_whole) *a_whole = std::max(aw, 0.0);
    return std::max(a, 0.0);
  };
  // The budgets the pieces leave at speed v: the acceleration with j = a/T, then the jerk (with
  // `whole`, the whole block's largest |g'''| on every piece).
  const auto budgets = [&](double v, bool whole = false) {
    RawLimits r{v, kInf, kInf};
    double a_whole = 0;
    const double a = accel_at(v, whole ? &a_whole : nullptr);
    r.accel = whole ? a_whole : a;
    for (int i = 0; i < kAxisCount; ++i) {
      if (d1[i] <= 0 || !limited_jerk(p, i)) continue;
      for (int q = 0; q < kIntervals; ++q) {
        const double G1 = pc.g1[i][q], G2 = pc.g2[i][q], G3 = whole ? d3[i] : pc.g3[i][q];
        if (G1 <= 0) continue;
        const double left = jerk_scale * p.machine[i].max_jerk - v * v * v * G3 - 3 * v * G2 * r.accel;
        r.jerk = std::min(r.jerk, std::max(left, 0.0) / G1);
      }
    }
    return r;
  };
  if (!jerk) return budgets(cap);
  // A budget already below kLowBudget of the axes' acceleration is what limits such a block:
  // it keeps the limits of the whole block's largest |g'''| (more budget there measured slower,
  // the tick's generator coasting more after accelerating harder).
  double a_whole = 0;
  const double a_ref = accel_at(std::min(cap, cap_jerk), &a_whole);
  if (a_whole < low_budget) return budgets(std::min(cap, cap_jerk), true);
  if (cap <= cap_jerk) return budgets(cap);
  // The highest speed up to `cap` at which every piece still leaves the budget a (0: none above
  // cap_jerk).
  const auto highest = [&](double a) {
    double v = cap;
    for (int i = 0; i < kAxisCount; ++i) {
      if (d1[i] <= 0 || !limited_jerk(p, i)) continue;
      const AxisLimits& l = p.machine[i];
      for (int q = 0; q < kIntervals; ++q) {
        const double G1 = pc.g1[i][q], G2 = pc.g2[i][q], G3 = pc.g3[i][q];
        const double room = jerk_scale * l.max_jerk - G1 * a / T;
        const double room_a = l.max_acceleration - G1 * a;
        if (room <= 0 || room_a < 0) return 0.0;
        if ((G3 * v * v + 3 * G2 * a) * v > room) v = std::min(v, cubic_speed(G3, 3 * G2 * a, room));
        if (G2 * v * v > room_a) v = std::sqrt(room_a / G2);
      }
    }
    return v;
  };
  // First without cost (the reference budget kept), then up to the nominal feed at the cost of
  // at most kTradedBudget of the budget, and never below the floor.
  double v = std::max(cap_jerk, highest(a_ref));
  const double need = std::min(cap, b.feed_class == traj::FeedClass::Feed && b.feed > 0 ? b.feed : kInf);
  const double a_traded = (1 - kTradedBudget) * a_ref;
  if (v < need && a_traded >= low_budget) v = std::max(v, std::min(need, highest(a_traded)));
  return budgets(v);
}

}  // namespace

namespace {

/// A Bernstein polynomial of degree n (coefficients c[0..n]) at t (de Casteljau).
double bernstein(const double* c, int n, double t) {
  double q[6];
  for (int k = 0; k <= n; ++k) q[k] = c[k];
  for (int level = n; level > 0; --level) {
    for (int k = 0; k < level; ++k) q[k] += t * (q[k + 1] - q[k]);
  }
  return q[0];
}

/// The roots in (0, 1) of a Bernstein polynomial of degree n ≤ 5, in order (at most n). Between
/// two consecutive roots of its derivative (found the same way) it is monotone, so each such piece
/// holds at most one root, found by bisection where the sign changes: no root is missed, however
/// close two of them lie.
int bernstein_roots(const double* c, int n, double* roots) {
  if (n <= 0) return 0;
  if (n == 1) {  // a line: its root in closed form
    if (c[0] == 0 || (c[0] < 0) == (c[1] < 0)) return 0;
    roots[0] = c[0] / (c[0] - c[1]);
    return 1;
  }
  double d[5];
  for (int k = 0; k < n; ++k) d[k] = n * (c[k + 1] - c[k]);
  double cuts[7];
  int nc = 0;
  cuts[nc++] = 0.0;
  double inner[5];
  const int ni = bernstein_roots(d, n - 1, inner);
  for (int k = 0; k < ni; ++k) cuts[nc++] = inner[k];
  cuts[nc++] = 1.0;
  int found = 0;
  for (int k = 0; k + 1 < nc; ++k) {
    double lo = cuts[k], hi = cuts[k + 1];
    double flo = bernstein(c, n, lo);
    double fhi = bernstein(c, n, hi);
    if (flo == 0 || (flo < 0) == (fhi < 0)) continue;
    // Regula falsi with the Illinois modification (the end kept twice has its value halved):
    // the bracket shrinks superlinearly, a few evaluations instead of bisection's 40.
    int kept = 0;
    for (int it = 0; it < 60 && hi - lo > 1e-12; ++it) {
      double x = (lo * fhi - hi * flo) / (fhi - flo);
      if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
      const double fx = bernstein(c, n, x);
      if (fx == 0) {
        lo = hi = x;
        break;
      }
      if ((fx < 0) == (flo < 0)) {
        lo = x;
        flo = fx;
        if (kept == -1) fhi *= 0.5;
        kept = -1;
      } else {
        hi = x;
        fhi = fx;
        if (kept == 1) flo *= 0.5;
        kept = 1;
      }
    }
    roots[found++] = 0.5 * (lo + hi);
  }
  return found;
}

/// Largest |p| on [0, 1] of a Bernstein polynomial of degree n ≤ 5: at the ends and at the roots
/// of p' (bernstein_roots), its extrema.
double max_abs_bernstein(const double* c, int n) {
  double best = std::max(std::fabs(c[0]), std::fabs(c[n]));
  if (n <= 1) return best;
  double d[5], roots[5];
  for (int k = 0; k < n; ++k) d[k] = n * (c[k + 1] - c[k]);
  const int nr = bernstein_roots(d, n - 1, roots);
  for (int k = 0; k < nr; ++k) best = std::max(best, std::fabs(bernstein(c, n, roots[k])));
  return best;
}

}  // namespace

// Per axis the derivatives of the Bézier in t are Béziers of the differences of the control
// points; their largest magnitudes on [0, 1], divided by L, L², L³, are those along s.
void derivative_bounds(const MotionBlock& b, double d1[kAxisCount], double d2[kAxisCount],
                       double d3[kAxisCount]) noexcept {
  const double L = b.length;
  const int n = b.kind == BlockKind::Quintic ? 5 : 3;
  for (int i = 0; i < kAxisCount; ++i) {
    double c[6], e1[5], e2[4], e3[3];
    bool moves = false;
    for (int k = 0; k <= n; ++k) {
      c[k] = traj::detail::quintic_point(b, k)[i];  // base, u, w, lin(, p4, p5)
      moves = moves || c[k] != c[0];
    }
    if (!moves) {  // an axis the block does not move
      d1[i] = d2[i] = d3[i] = 0;
      continue;
    }
    for (int k = 0; k < n; ++k) e1[k] = n * (c[k + 1] - c[k]);
    for (int k = 0; k < n - 1; ++k) e2[k] = (n - 1) * (e1[k + 1] - e1[k]);
    for (int k = 0; k < n - 2; ++k) e3[k] = (n - 2) * (e2[k + 1] - e2[k]);
    d1[i] = max_abs_bernstein(e1, n - 1) / L;
    d2[i] = max_abs_bernstein(e2, n - 2) / (L * L);
    d3[i] = max_abs_bernstein(e3, n - 3) / (L * L * L);
  }
}

RawLimits block_limits(const MotionBlock& b, double v_commanded_max, const LimitParams& p,
                       double jerk_scale) noexcept {
  switch (b.kind) {
    case BlockKind::Line:
      return line_limits(b, v_commanded_max, p, jerk_scale);
    case BlockKind::Arc:
    case BlockKind::Spiral:
      return arc_or_spiral_limits(b, v_commanded_max, p, jerk_scale);
    case BlockKind::Bezier:
    case BlockKind::Quintic:
      return bezier_limits(b, v_commanded_max, p, jerk_scale);
    case BlockKind::Marker:
      break;
  }
  return {kInf, kInf, kInf};
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
