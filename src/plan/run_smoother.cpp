// SPDX-License-Identifier: GPL-3.0-or-later
// A run of short feed lines as one least-squares cubic B-spline within the tolerance (C2 spans).
//
// The curve C(u) = Σ N_i(u/h − i)·P_i is a uniform cubic B-spline over the chord length u of the
// run's vertices Q_0 … Q_n, with m spans of length h = U/m. At the run's end it is natural
// (P_{m+1} = 2P_m − P_{m−1}, P_m = Q_n: the curve ends on the last vertex with no curvature, where
// a blend takes over); at its start too, or, where the run continues a fitted one, P_{−1}, P_0, P_1
// are those that give the point, C' and C'' the curve had there: from C = (P_{−1} + 4P_0 + P_1)/6,
// C' = (P_1 − P_{−1})/2h and C'' = (P_{−1} − 2P_0 + P_1)/h², P_0 = C − h²C''/6 and
// P_{±1} = P_0 ± h·C' + h²C''/2. The free control points minimise
// Σ_k |C(u_k) − Q_k|² + λ·Σ_i |Δ²P_i|² (λ small: it only fixes control points of spans without a
// vertex); the normal equations are banded (half-width 3) and positive definite, solved by
// Cholesky. With few spans the fit averages the vertices' rounding and CAM noise away; the number
// of spans doubles until every span stays within the tolerance of the moves (span_within).
#include "run_smoother.hpp"

#include <algorithm>
#include <cmath>

#include "path_geometry.hpp"
#include "vec.hpp"

namespace opencnc::plan::detail {

using traj::BlockKind;
using traj::FeedClass;

namespace {

constexpr long kBand = 3;            ///< half bandwidth of the normal equations
constexpr double kSmoothing = 1e-4;  ///< λ relative to the data's weight per control point

/// Uniform cubic B-spline basis at t ∈ [0, 1] for control points j−1 … j+2.
void basis(double t, double w[4]) {
  const double r = 1 - t, t2 = t * t, t3 = t2 * t;
  w[0] = r * r * r / 6;
  w[1] = (3 * t3 - 6 * t2 + 4) / 6;
  w[2] = (-3 * t3 + 3 * t2 + 3 * t + 1) / 6;
  w[3] = t3 / 6;
}

/// The point of the line moves [lo, hi] nearest to `x`: its move and distance.
struct Nearest {
  double d = 1e300;
  std::size_t k = 0;
  Pose p{};
};

Nearest nearest_line(const std::vector<Element>& moves, std::size_t lo, std::size_t hi, const Pose& x) {
  Nearest n;
  for (std::size_t k = lo; k <= hi; ++k) {
    const traj::MotionBlock& b = moves[k].b;  // a line: unit direction `lin`
    const Pose q = b.base + std::clamp(dot(x - b.base, b.lin), 0.0, b.length) * b.lin;
    const double d = norm(x - q);
    if (d < n.d) n = {d, k, q};
  }
  return n;
}

/// Whether every point of the cubic Bézier span `c` lies within `tol` of the line moves
/// [lo, hi] (consecutive, each starting where the one before ends). Branch and bound on
/// intervals [a, b] of its parameter with two bounds on the distance between samples:
/// - first order: the distance is 1-Lipschitz and the curve moves at most Lip·(b − a), so it
///   stays within (d_a + d_b + Lip·(b − a))/2 (as curve_within);
/// - second order: the curve stays within (b − a)²/8 · max|C''| of the chord from C(a) to C(b)
///   (linear interpolation error); a chord point (1 − λ)C(a) + λC(b) is within (1 − λ)d_a + λd_b
///   of (1 − λ)n_a + λn_b, n_a and n_b the nearest points of the moves; when both lie on one move
///   that point is on it, when on two neighbours it is within H of them (H the height of their
///   common vertex above the line n_a n_b: the base of the triangle n_a, vertex, n_b is within
///   its height of the other two sides). So the distance is at most max(d_a, d_b) + H + (b − a)²/8 ·
///   max|C''|, which for a smooth fit holds on intervals as long as a move rather than the
///   thousandth of a span the first order needs near the tolerance.
bool span_within(const traj::MotionBlock& c, const std::vector<Element>& moves, std::size_t lo,
                 std::size_t hi, double tol) {
  const Pose q[4] = {c.base, c.u, c.w, c.lin};
  const double lip = 3 * std::max({norm(q[1] - q[0]), norm(q[2] - q[1]), norm(q[3] - q[2])});
  const double m2 = 6 * std::max(norm(q[2] - 2.0 * q[1] + q[0]), norm(q[3] - 2.0 * q[2] + q[1]));
  const auto at = [&](double t) { return nearest_line(moves, lo, hi, traj::position_at(c, c.length * t)); };
  const auto second_order = [&](const Nearest& na, const Nearest& nb, double dt) {
    double height = 0;
    if (na.k != nb.k) {
      if (na.k + 1 != nb.k && nb.k + 1 != na.k) return 1e300;  // farther apart: not this bound
      const Pose v = end_point(moves[std::min(na.k, nb.k)].b);
      const Pose base = nb.p - na.p;
      const double len2 = dot(base, base);
      const Pose w = v - na.p;
      height = len2 > 0 ? norm(w - (dot(w, base) / len2) * base) : norm(w);
    }
    return std::max(na.d, nb.d) + height + 0.125 * dt * dt * m2;
  };
  constexpr int kStart = 4, kMaxSamples = 4096, kDepth = 64;
  struct Span {
    double a, b;
    Nearest na, nb;
  };
  Span stack[kDepth];
  int samples = kStart + 1;
  Nearest na = at(0.0);
  if (na.d > tol) return false;
  for (int i = 1; i <= kStart; ++i) {
    const double t1 = static_cast<double>(i) / kStart;
    const Nearest nb = at(t1);
    if (nb.d > tol) return false;
    int top = 0;
    stack[top++] = {static_cast<double>(i - 1) / kStart, t1, na, nb};
    while (top > 0) {
      const Span sp = stack[--top];
      const double dt = sp.b - sp.a;
      if (0.5 * (sp.na.d + sp.nb.d + lip * dt) <= tol || second_order(sp.na, sp.nb, dt) <= tol) continue;
      if (top + 2 > kDepth || ++samples > kMaxSamples) return false;  // too close to call: not within
      const double m = 0.5 * (sp.a + sp.b);
      const Nearest nm = at(m);
      if (nm.d > tol) return false;
      stack[top++] = {m, sp.b, nm, sp.nb};
      stack[top++] = {sp.a, m, sp.na, nm};
    }
    na = nb;
  }
  return true;
}

bool only_xyz(const traj::MotionBlock& b) {
  for (int i = 3; i < kAxisCount; ++i) {
    if (b.lin[i] != 0) return false;
  }
  return true;
}

}  // namespace

bool RunSmoother::accepts(const Element& e) const {
  const traj::MotionBlock& b = e.b;
  if (b.kind != BlockKind::Line || b.feed_class != FeedClass::Feed || e.stop_after) return false;
  if (e.mode != canon::MotionControl::Continuous || b.length > p_.max_move || !only_xyz(b)) return false;
  if (run_.empty()) return true;
  const Element& last = run_.back();
  if (e.tolerance != last.tolerance || b.flags != last.b.flags || b.feed != last.b.feed) return false;
  return angle_between(last.b.lin, b.lin) <= p_.max_turn;
}

double RunSmoother::fit_tolerance() const {
  double merged = 0, shortest = 1e300;
  for (const Element& e : run_) {
    merged = std::max(merged, e.merge_deviation);
    shortest = std::min(shortest, e.b.length);
  }
  const double tol = run_.front().tolerance;
  return (tol > 0 ? 0.5 * tol : p_.free_share * shortest) - merged;
}

void RunSmoother::flush(std::vector<Element>& out) {
  emit(false, out);
}

void RunSmoother::flush_part(std::vector<Element>& out) {
  emit(true, out);
}

// Fits the run with ever more spans; `partial`: only the spans before the last quarter of the
// moves go out, and the rest of the run stays to be fitted on from there.
void RunSmoother::emit(bool partial, std::vector<Element>& out) {
  const std::size_t n = run_.size();
  const double tol = n > 0 ? fit_tolerance() : 0;
  bool done = false;
  if ((n >= 3 || (continued_ && n >= 1)) && tol > 1e-6) {
    const std::size_t least = continued_ ? 2 : 1;
    for (std::size_t spans = std::max(least, n / 8); !done; spans *= 2) {
      spans = std::min(spans, std::max(n, least));
      done = fit(spans, tol, partial, out);
      if (spans >= std::max(n, least)) break;
    }
  }
  if (done) {
    ++fitted_;
    return;
  }
  // As they came; after a fitted part, a line from where it ended to the first move's end.
  std::size_t from = 0;
  if (continued_ && n > 0) {
    Element e = run_[0];
    if (make_line(start_.p, end_point(run_[0].b), e.b)) {
      e.orig_length = e.b.length;
      e.merge_deviation = std::max(0.0, tol) + run_[0].merge_deviation;
      out.push_back(e);
    }
    from = 1;
  }
  out.insert(out.end(), run_.begin() + static_cast<long>(from), run_.end());
  run_.clear();
  continued_ = false;
}

bool RunSmoother::fit(std::size_t m, double tolerance, bool partial, std::vector<Element>& out) {
  const std::size_t n = run_.size();
  const long M = static_cast<long>(m);
  points_.resize(n + 1);
  u_.resize(n + 1);
  points_[0] = continued_ ? start_.p : run_[0].b.base;
  u_[0] = 0;
  for (std::size_t k = 0; k < n; ++k) {
    points_[k + 1] = end_point(run_[k].b);
    u_[k + 1] = u_[k] + (k == 0 && continued_ ? norm(points_[1] - points_[0]) : run_[k].b.length);
  }
  const double U = u_[n];
  if (!(U > 0)) return false;
  const double h = U / static_cast<double>(m);
  // Control points P_{−1} … P_{m+1} at index i + 1; the free ones are P_first … P_{m−1}.
  control_.assign(m + 3, Pose{});
  const auto at = [&](long i) -> Pose& { return control_[static_cast<std::size_t>(i + 1)]; };
  at(M) = points_[n];
  long first = 1;
  if (continued_) {
    const Pose c2 = (h * h) * start_.d2;
    at(0) = start_.p - (1.0 / 6) * c2;
    at(1) = at(0) + h * start_.d1 + 0.5 * c2;
    at(-1) = at(0) - h * start_.d1 + 0.5 * c2;
    first = 2;
  } else {
    at(0) = points_[0];
  }
  if (first > M) return false;
  const std::size_t free = static_cast<std::size_t>(M - first);
  band_.assign(free * (kBand + 1), 0.0);
  rhs_.assign(free, Pose{});
  const auto band = [&](std::size_t r, std::size_t c) -> double& {  // lower triangle, r ≥ c
    return band_[r * (kBand + 1) + (r - c)];
  };
  const auto is_free = [&](long i) { return i >= first && i <= M - 1; };
  // One equation Σ w_q·P_{idx_q} ≈ target of weight `weight`, the phantom ends in terms of the others.
  const auto add_row = [&](const long idx[], const double w[], int count, const Pose& target, double weight) {
    double coef[6] = {};
    long var[6] = {};
    int nv = 0;
    Pose fixed{};
    const auto put = [&](long i, double c) {
      if (!is_free(i)) {
        fixed = fixed + c * at(i);
        return;
      }
      for (int q = 0; q < nv; ++q) {
        if (var[q] == i) {
          coef[q] += c;
          return;
        }
      }
      var[nv] = i;
      coef[nv++] = c;
    };
    for (int q = 0; q < count; ++q) {
      const long i = idx[q];
      if (i == -1 && !continued_) {  // P_{−1} = 2·P_0 − P_1
        put(0, 2 * w[q]);
        put(1, -w[q]);
      } else if (i == M + 1) {  // P_{m+1} = 2·P_m − P_{m−1}
        put(M, 2 * w[q]);
        put(M - 1, -w[q]);
      } else {
        put(i, w[q]);
      }
    }
    const Pose r = target - fixed;
    for (int a = 0; a < nv; ++a) {
      const auto ra = static_cast<std::size_t>(var[a] - first);
      rhs_[ra] = rhs_[ra] + (weight * coef[a]) * r;
      for (int b = 0; b < nv; ++b) {
        const auto rb = static_cast<std::size_t>(var[b] - first);
        if (rb <= ra) band(ra, rb) += weight * coef[a] * coef[b];
      }
    }
  };
  for (std::size_t k = 0; k <= n; ++k) {
    const double x = u_[k] / h;
    const long j = std::min(M - 1, static_cast<long>(std::floor(x)));
    double w[4];
    basis(x - static_cast<double>(j), w);
    const long idx[4] = {j - 1, j, j + 1, j + 2};
    add_row(idx, w, 4, points_[k], 1.0);
  }
  const double lambda = kSmoothing * static_cast<double>(n + 1) / static_cast<double>(m);
  for (long i = 0; i <= M; ++i) {
    const long idx[3] = {i - 1, i, i + 1};
    const double w[3] = {1, -2, 1};
    add_row(idx, w, 3, Pose{}, lambda);
  }
  // Banded Cholesky N = L·Lᵀ, then L·y = rhs, Lᵀ·x = y.
  const auto lo = [](std::size_t r) { return r >= static_cast<std::size_t>(kBand) ? r - kBand : 0; };
  for (std::size_t r = 0; r < free; ++r) {
    for (std::size_t c = lo(r); c <= r; ++c) {
      double sum = band(r, c);
      for (std::size_t k = lo(r); k < c; ++k) sum -= band(r, k) * band(c, k);
      if (c == r) {
        if (!(sum > 0)) return false;
        band(r, r) = std::sqrt(sum);
      } else {
        band(r, c) = sum / band(c, c);
      }
    }
  }
  for (std::size_t r = 0; r < free; ++r) {
    Pose sum = rhs_[r];
    for (std::size_t k = lo(r); k < r; ++k) sum = sum - band(r, k) * rhs_[k];
    rhs_[r] = (1.0 / band(r, r)) * sum;
  }
  for (std::size_t r = free; r-- > 0;) {
    Pose sum = rhs_[r];
    for (std::size_t k = r + 1; k < free && k - r <= static_cast<std::size_t>(kBand); ++k) {
      sum = sum - band(k, r) * rhs_[k];
    }
    rhs_[r] = (1.0 / band(r, r)) * sum;
  }
  for (long i = first; i < M; ++i) at(i) = rhs_[static_cast<std::size_t>(i - first)];
  if (!continued_) at(-1) = 2.0 * at(0) - at(1);
  at(M + 1) = 2.0 * at(M) - at(M - 1);

  // The spans that go out: all, or (a part) those before the last quarter of the moves.
  long last_span = M;
  if (partial) {
    const std::size_t keep = std::max<std::size_t>(1, n / 4);
    last_span = static_cast<long>(std::floor(u_[n - keep] / h));
    if (last_span < 1 || last_span >= M) last_span = M;  // too short to leave a tail
  }
  // Each span as a cubic Bézier, checked against the moves within a span of its range.
  const std::size_t first_out = out.size();
  std::size_t k_lo = 0, near_a = 0, near_b = 0;
  for (long j = 0; j < last_span; ++j) {
    const double u0 = static_cast<double>(j) * h, u1 = u0 + h;
    const Pose a = at(j - 1), b = at(j), c = at(j + 1), d = at(j + 2);
    while (k_lo + 1 < n && u_[k_lo + 1] <= u0) ++k_lo;  // the move the span starts on
    std::size_t k_hi = k_lo;
    while (k_hi + 1 < n && u_[k_hi + 1] < u1) ++k_hi;  // and ends on
    Element e = run_[k_lo];
    traj::MotionBlock& s = e.b;
    s.kind = BlockKind::Bezier;
    s.base = (1.0 / 6) * (a + 4.0 * b + c);
    s.u = (1.0 / 3) * (2.0 * b + c);
    s.w = (1.0 / 3) * (b + 2.0 * c);
    s.lin = (1.0 / 6) * (b + 4.0 * c + d);
    if (j == 0) s.base = points_[0];  // exactly (the end conditions give it up to rounding)
    if (j + 1 == M) s.lin = points_[n];
    s.length = h;  // dp/ds = dC/du: C2 in s across the spans
    s.omega = 0;
    s.segment = run_[k_lo].b.segment_first;
    s.segment_first = run_[k_lo].b.segment_first;
    s.segment_last = run_[k_hi].b.segment_last;
    s.segment_offset = 0;
    // Checked against the moves within a span's length of it, [near_a, near_b] (u_ grows with k,
    // and so do the spans, so both ends only move forward): a subset of the path, so the
    // distance to it bounds the distance to the path from above.
    const double near_lo = u0 - h, near_hi = u1 + h;
    while (near_a + 1 < n && u_[near_a + 1] < near_lo) ++near_a;
    near_b = std::max(near_b, near_a);
    while (near_b + 1 < n && u_[near_b + 1] <= near_hi) ++near_b;
    if (!span_within(s, run_, near_a, near_b, tolerance)) {
      out.resize(first_out);
      return false;
    }
    // The spans at the run's ends meet blends, which may use what the span leaves of the
    // tolerance: its own deviation, to within a factor of two.
    double deviation = tolerance;
    if (j == 0 || j + 1 == M) {
      for (double share = 0.125; share < 1; share *= 2) {
        if (span_within(s, run_, near_a, near_b, share * tolerance)) {
          deviation = share * tolerance;
          break;
        }
      }
    }
    e.orig_length = h;
    e.merge_deviation = deviation;  // the run's own merges added below
    out.push_back(e);
  }
  // The other way round: every vertex the spans pass stays within the tolerance of the curve
  // (the fit must not cut a corner of the moves off, whatever its distance to them).
  const double covered = static_cast<double>(last_span) * h;
  for (std::size_t k = 1; k < n && u_[k] < covered; ++k) {
    const long j = std::min(last_span - 1, static_cast<long>(std::floor(u_[k] / h)));
    const traj::MotionBlock& span = out[first_out + static_cast<std::size_t>(j)].b;
    if (norm(traj::position_at(span, u_[k] - static_cast<double>(j) * h) - points_[k]) <= tolerance) continue;
    double best = 1e300;
    for (long q = std::max(0L, j - 1); q <= std::min(last_span - 1, j + 1); ++q)
      best = std::min(best, point_to_curve(out[first_out + static_cast<std::size_t>(q)].b, points_[k]));
    if (best > tolerance) {
      out.resize(first_out);
      return false;
    }
  }
  double merged = 0;
  for (const Element& e : run_) merged = std::max(merged, e.merge_deviation);
  for (std::size_t q = first_out; q < out.size(); ++q) out[q].merge_deviation += merged;
  if (last_span == M) {
    run_.clear();
    continued_ = false;
    return true;
  }
  // The rest continues from the cut with the curve's point, C' and C'' there.
  const Pose a = at(last_span - 1), b = at(last_span), c = at(last_span + 1);
  start_.p = out.back().b.lin;
  start_.d1 = (0.5 / h) * (c - a);
  start_.d2 = (1.0 / (h * h)) * (a - 2.0 * b + c);
  const double cut = static_cast<double>(last_span) * h;
  std::size_t k = 0;
  while (k + 1 < n && u_[k + 1] <= cut) ++k;  // the move the cut lies on stays
  run_.erase(run_.begin(), run_.begin() + static_cast<long>(k));
  continued_ = true;
  return true;
}

}  // namespace opencnc::plan::detail
