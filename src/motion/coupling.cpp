// SPDX-License-Identifier: GPL-3.0-or-later
// CouplingLaw: the slave's offset, slope and curvature for each law (closed forms of 360·∫dz/p(z),
// cubic Hermite cams), and their extremes over a master interval for the preflight.
#include "opencnc/motion/coupling.hpp"

#include <algorithm>
#include <cmath>

namespace opencnc::motion {

namespace {

constexpr double kDegPerRev = 360.0;
/// Below this |k·x/p| the logarithm's series is used (log1p loses nothing, but k → 0 divides).
constexpr double kSmallRate = 1e-12;

/// Revolutions over x mm of a pitch p + k·z (z from 0 to x): ∫ dz/(p + k z) = ln(1 + k x/p)/k.
/// A pitch that would reach zero is held just above it (the preflight refuses such moves).
double revolutions(double p, double k, double x) noexcept {
  const double q = k * x / p;
  if (std::fabs(q) < kSmallRate) return x / p;
  return std::log1p(std::max(q, -1.0 + 1e-9)) / k;
}

struct Hermite {
  double h00, h10, h01, h11;
};

}  // namespace

CouplingLaw CouplingLaw::constant(double pitch_mm) noexcept {
  CouplingLaw l;
  l.kind_ = CouplingKind::ConstantPitch;
  l.pitch_ = pitch_mm;
  return l;
}

CouplingLaw CouplingLaw::linear(double pitch_mm, double rate) noexcept {
  CouplingLaw l;
  l.kind_ = CouplingKind::LinearPitch;
  l.pitch_ = pitch_mm;
  l.rate_ = rate;
  return l;
}

// Derived data: a pitch table's integral at each point (revolutions from the first point), a
// cam's slope at each point (the three-point derivative for unequal spacing; the chord's at the
// ends, so the linear continuation beyond them keeps the slope: C1 everywhere).
CouplingLaw CouplingLaw::tabulated(CouplingKind kind, const CouplingTable& table) noexcept {
  CouplingLaw l;
  l.kind_ = kind;
  l.table_ = table;
  l.table_.count = std::clamp(table.count, 1, kMaxCouplingPoints);
  const int n = l.table_.count;
  const auto& m = l.table_.master;
  const auto& v = l.table_.value;
  if (kind == CouplingKind::PitchTable) {
    l.derived_[0] = 0;
    for (int i = 0; i + 1 < n; ++i) {
      const double h = m[i + 1] - m[i];
      const double k = (v[i + 1] - v[i]) / h;
      l.derived_[i + 1] = l.derived_[i] + revolutions(v[i], k, h);
    }
    l.origin_ = 0;
    l.origin_ = l.pitch_integral(0.0);
  } else {
    for (int i = 0; i < n; ++i) {
      if (n == 1) {
        l.derived_[0] = 0;
      } else if (i == 0 || i == n - 1) {
        const int a = i == 0 ? 0 : n - 2;
        l.derived_[i] = (v[a + 1] - v[a]) / (m[a + 1] - m[a]);
      } else {
        const double h0 = m[i] - m[i - 1], h1 = m[i + 1] - m[i];
        const double d0 = (v[i] - v[i - 1]) / h0, d1 = (v[i + 1] - v[i]) / h1;
        l.derived_[i] = (h1 * d0 + h0 * d1) / (h0 + h1);
      }
    }
    l.origin_ = 0;
    l.origin_ = l.cam_value(0.0);
  }
  return l;
}

// Largest i with master[i] <= d among the points (−1 before the first). Bounded binary search.
int CouplingLaw::segment(double d) const noexcept {
  const auto& m = table_.master;
  if (d < m[0]) return -1;
  int lo = 0, hi = table_.count - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (m[mid] <= d) {
      lo = mid;
    } else {
      hi = mid - 1;
    }
  }
  return lo;
}

double CouplingLaw::pitch_integral(double d) const noexcept {
  const auto& m = table_.master;
  const auto& v = table_.value;
  const int n = table_.count;
  const int i = segment(d);
  if (i < 0) return (d - m[0]) / v[0] - origin_;
  if (i >= n - 1) return derived_[n - 1] + (d - m[n - 1]) / v[n - 1] - origin_;
  const double k = (v[i + 1] - v[i]) / (m[i + 1] - m[i]);
  return derived_[i] + revolutions(v[i], k, d - m[i]) - origin_;
}

double CouplingLaw::cam_value(double d) const noexcept {
  const auto& m = table_.master;
  const auto& v = table_.value;
  const int n = table_.count;
  const int i = segment(d);
  if (i < 0) return v[0] + derived_[0] * (d - m[0]) - origin_;
  if (i >= n - 1) return v[n - 1] + derived_[n - 1] * (d - m[n - 1]) - origin_;
  const double h = m[i + 1] - m[i];
  const double u = (d - m[i]) / h;
  const double u2 = u * u, u3 = u2 * u;
  const Hermite b{2 * u3 - 3 * u2 + 1, u3 - 2 * u2 + u, -2 * u3 + 3 * u2, u3 - u2};
  return b.h00 * v[i] + b.h10 * h * derived_[i] + b.h01 * v[i + 1] + b.h11 * h * derived_[i + 1] - origin_;
}

double CouplingLaw::pitch_at(double d) const noexcept {
  switch (kind_) {
    case CouplingKind::ConstantPitch:
      return pitch_;
    case CouplingKind::LinearPitch:
      return pitch_ + rate_ * d;
    case CouplingKind::PitchTable: {
      const int i = segment(d);
      const int n = table_.count;
      if (i < 0) return table_.value[0];
      if (i >= n - 1) return table_.value[n - 1];
      const double u = (d - table_.master[i]) / (table_.master[i + 1] - table_.master[i]);
      return table_.value[i] + u * (table_.value[i + 1] - table_.value[i]);
    }
    default:
      return 0;
  }
}

double CouplingLaw::slave(double d) const noexcept {
  switch (kind_) {
    case CouplingKind::ConstantPitch:
      return kDegPerRev * d / pitch_;
    case CouplingKind::LinearPitch:
      return kDegPerRev * revolutions(pitch_, rate_, d);
    case CouplingKind::PitchTable:
      return kDegPerRev * pitch_integral(d);
    case CouplingKind::Cam:
      return cam_value(d);
    case CouplingKind::Off:
      break;
  }
  return 0;
}

double CouplingLaw::slope(double d) const noexcept {
  if (kind_ == CouplingKind::Off) return 0;
  if (kind_ != CouplingKind::Cam) return kDegPerRev / pitch_at(d);
  const auto& m = table_.master;
  const auto& v = table_.value;
  const int n = table_.count;
  const int i = segment(d);
  if (i < 0) return derived_[0];
  if (i >= n - 1) return derived_[n - 1];
  const double h = m[i + 1] - m[i];
  const double u = (d - m[i]) / h;
  return (6 * u * u - 6 * u) * (v[i] - v[i + 1]) / h + (3 * u * u - 4 * u + 1) * derived_[i] +
         (3 * u * u - 2 * u) * derived_[i + 1];
}

double CouplingLaw::curvature(double d) const noexcept {
  switch (kind_) {
    case CouplingKind::LinearPitch: {
      const double p = pitch_at(d);
      return -kDegPerRev * rate_ / (p * p);
    }
    case CouplingKind::PitchTable: {
      const int i = segment(d);
      if (i < 0 || i >= table_.count - 1) return 0;
      const double k = (table_.value[i + 1] - table_.value[i]) / (table_.master[i + 1] - table_.master[i]);
      const double p = pitch_at(d);
      return -kDegPerRev * k / (p * p);
    }
    case CouplingKind::Cam: {
      const auto& m = table_.master;
      const auto& v = table_.value;
      const int i = segment(d);
      if (i < 0 || i >= table_.count - 1) return 0;
      const double h = m[i + 1] - m[i];
      const double u = (d - m[i]) / h;
      return ((12 * u - 6) * (v[i] - v[i + 1]) / h + (6 * u - 4) * derived_[i] +
              (6 * u - 2) * derived_[i + 1]) /
             h;
    }
    default:
      return 0;
  }
}

// Candidates: the ends, every table point inside (each side of it for the curvature, which may
// jump there), and a cam segment's slope vertex.
double CouplingLaw::max_slope(double a, double b) const noexcept {
  if (a > b) std::swap(a, b);
  double best = std::max(std::fabs(slope(a)), std::fabs(slope(b)));
  if (kind_ == CouplingKind::LinearPitch || kind_ == CouplingKind::ConstantPitch ||
      kind_ == CouplingKind::Off)
    return best;
  const auto& m = table_.master;
  const auto& v = table_.value;
  for (int i = 0; i < table_.count; ++i) {
    if (m[i] > a && m[i] < b) best = std::max(best, std::fabs(slope(m[i])));
    if (kind_ != CouplingKind::Cam || i + 1 >= table_.count) continue;
    const double h = m[i + 1] - m[i];
    const double qa = 6 * (v[i] - v[i + 1]) / h + 3 * derived_[i] + 3 * derived_[i + 1];
    const double qb = -6 * (v[i] - v[i + 1]) / h - 4 * derived_[i] - 2 * derived_[i + 1];
    if (qa == 0) continue;
    const double x = m[i] + h * (-qb / (2 * qa));
    if (x > a && x < b && x > m[i] && x < m[i + 1]) best = std::max(best, std::fabs(slope(x)));
  }
  return best;
}

std::pair<double, double> CouplingLaw::slave_extent(double a, double b) const noexcept {
  if (a > b) std::swap(a, b);
  double lo = std::min(slave(a), slave(b)), hi = std::max(slave(a), slave(b));
  if (kind_ != CouplingKind::Cam) return {lo, hi};  // the pitch laws are monotone
  const auto& m = table_.master;
  const auto& v = table_.value;
  const auto take = [&](double x) {
    if (!(x > a && x < b)) return;
    const double s = slave(x);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  };
  for (int i = 0; i + 1 < table_.count; ++i) {
    const double h = m[i + 1] - m[i];
    const double qa = 6 * (v[i] - v[i + 1]) / h + 3 * derived_[i] + 3 * derived_[i + 1];
    const double qb = -6 * (v[i] - v[i + 1]) / h - 4 * derived_[i] - 2 * derived_[i + 1];
    const double qc = derived_[i];
    double roots[2] = {-1, -1};
    if (std::fabs(qa) < 1e-15) {
      if (qb != 0) roots[0] = -qc / qb;
    } else if (const double disc = qb * qb - 4 * qa * qc; disc >= 0) {
      roots[0] = (-qb - std::sqrt(disc)) / (2 * qa);
      roots[1] = (-qb + std::sqrt(disc)) / (2 * qa);
    }
    for (double u : roots) {
      if (u > 0 && u < 1) take(m[i] + h * u);
    }
  }
  return {lo, hi};
}

double CouplingLaw::max_curvature(double a, double b) const noexcept {
  if (a > b) std::swap(a, b);
  double best = std::max(std::fabs(curvature(a)), std::fabs(curvature(b)));
  if (kind_ != CouplingKind::PitchTable && kind_ != CouplingKind::Cam) return best;
  const auto& m = table_.master;
  for (int i = 0; i < table_.count; ++i) {
    if (!(m[i] > a && m[i] < b)) continue;
    best = std::max(best, std::fabs(curvature(m[i])));
    // The segment ending at m[i], evaluated at its end (curvature() takes the one starting there).
    if (i > 0) {
      const double left = std::nextafter(m[i], m[i - 1]);
      best = std::max(best, std::fabs(curvature(left)));
    }
  }
  return best;
}

CouplingLaw law_for(const CouplingConfig& config, CouplingKind kind, double pitch_mm, double rate,
                    int table) noexcept {
  switch (kind) {
    case CouplingKind::ConstantPitch:
      return CouplingLaw::constant(pitch_mm);
    case CouplingKind::LinearPitch:
      return CouplingLaw::linear(pitch_mm, rate);
    case CouplingKind::PitchTable:
    case CouplingKind::Cam: {
      const int t = table - 1;
      if (t < 0 || t >= kMaxCouplingTables || config.table_kind[static_cast<std::size_t>(t)] != kind)
        return {};
      return CouplingLaw::tabulated(kind, config.tables[static_cast<std::size_t>(t)]);
    }
    case CouplingKind::Off:
      break;
  }
  return {};
}

}  // namespace opencnc::motion
