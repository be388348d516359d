// SPDX-License-Identifier: GPL-3.0-or-later
// Closed-form evaluation of a motion block's geometry at a path parameter: position and its first
// and second derivatives with respect to s.
#pragma once

#include <cmath>

#include "opencnc/traj/motion_block.hpp"

namespace opencnc::traj {

namespace detail {

/// Bernstein weights of degree 5 at t.
inline void quintic_weights(double t, double w[6]) noexcept {
  const double r = 1.0 - t, t2 = t * t, r2 = r * r;
  w[0] = r2 * r2 * r;
  w[1] = 5 * r2 * r2 * t;
  w[2] = 10 * r2 * r * t2;
  w[3] = 10 * r2 * t2 * t;
  w[4] = 5 * r * t2 * t2;
  w[5] = t2 * t2 * t;
}

/// The k-th control point of a quintic block (0: base … 5: p5).
inline const Pose& quintic_point(const MotionBlock& b, int k) noexcept {
  switch (k) {
    case 0:
      return b.base;
    case 1:
      return b.u;
    case 2:
      return b.w;
    case 3:
      return b.lin;
    case 4:
      return b.p4;
    default:
      return b.p5;
  }
}

}  // namespace detail

/// Position of block `b` at path parameter s ∈ [0, b.length]. Any thread; real-time safe.
inline Pose position_at(const MotionBlock& b, double s) noexcept {
  Pose p;
  switch (b.kind) {
    case BlockKind::Line:
      for (int i = 0; i < kAxisCount; ++i) p[i] = b.base[i] + s * b.lin[i];
      break;
    case BlockKind::Arc: {
      // 1 − cos x written as 2·sin²(x/2): no cancellation for the huge radii of near-straight blends.
      const double sn = std::sin(b.omega * s), h = std::sin(0.5 * b.omega * s), vers = 2.0 * h * h;
      for (int i = 0; i < kAxisCount; ++i) p[i] = b.base[i] + sn * b.w[i] + vers * b.u[i] + s * b.lin[i];
      break;
    }
    case BlockKind::Spiral: {
      // The arc's terms, plus the radius change along the radius vector sin θ·w − cos θ·u.
      const double th = b.omega * s, sn = std::sin(th), cs = std::cos(th), h = std::sin(0.5 * th);
      const double vers = 2.0 * h * h, grow = b.spiral * th;
      for (int i = 0; i < kAxisCount; ++i) {
        p[i] = b.base[i] + sn * b.w[i] + vers * b.u[i] + grow * (sn * b.w[i] - cs * b.u[i]) + s * b.lin[i];
      }
      break;
    }
    case BlockKind::Bezier: {
      const double t = b.length > 0 ? s / b.length : 0.0, r = 1.0 - t;
      const double k0 = r * r * r, k1 = 3 * r * r * t, k2 = 3 * r * t * t, k3 = t * t * t;
      for (int i = 0; i < kAxisCount; ++i) p[i] = k0 * b.base[i] + k1 * b.u[i] + k2 * b.w[i] + k3 * b.lin[i];
      break;
    }
    case BlockKind::Quintic: {
      double k[6];
      detail::quintic_weights(b.length > 0 ? s / b.length : 0.0, k);
      for (int i = 0; i < kAxisCount; ++i) {
        p[i] = k[0] * b.base[i] + k[1] * b.u[i] + k[2] * b.w[i] + k[3] * b.lin[i] + k[4] * b.p4[i] +
               k[5] * b.p5[i];
      }
      break;
    }
    case BlockKind::Marker:
      p = b.base;
      break;
  }
  return p;
}

/// dp/ds of block `b` at s (unit length for lines and arcs; for a spiral close to it, varying
/// with the radius). Any thread; real-time safe.
inline Pose tangent_at(const MotionBlock& b, double s) noexcept {
  Pose d;
  switch (b.kind) {
    case BlockKind::Line:
      d = b.lin;
      break;
    case BlockKind::Arc: {
      const double c = std::cos(b.omega * s), sn = std::sin(b.omega * s);
      for (int i = 0; i < kAxisCount; ++i) d[i] = b.omega * (c * b.w[i] + sn * b.u[i]) + b.lin[i];
      break;
    }
    case BlockKind::Spiral: {
      // d/dθ: (1 + ρθ)·(cos θ·w + sin θ·u) + ρ·(sin θ·w − cos θ·u), times ω.
      const double th = b.omega * s, c = std::cos(th), sn = std::sin(th), a = 1.0 + b.spiral * th;
      for (int i = 0; i < kAxisCount; ++i) {
        d[i] = b.omega * (a * (c * b.w[i] + sn * b.u[i]) + b.spiral * (sn * b.w[i] - c * b.u[i])) + b.lin[i];
      }
      break;
    }
    case BlockKind::Bezier: {
      const double t = b.length > 0 ? s / b.length : 0.0, r = 1.0 - t, k = 3.0 / b.length;
      for (int i = 0; i < kAxisCount; ++i) {
        d[i] =
            k * (r * r * (b.u[i] - b.base[i]) + 2 * r * t * (b.w[i] - b.u[i]) + t * t * (b.lin[i] - b.w[i]));
      }
      break;
    }
    case BlockKind::Quintic: {
      // 5·Σ ΔP_k·B⁴_k(t), per unit of s: the derivative of a Bézier is the Bézier of its differences.
      const double t = b.length > 0 ? s / b.length : 0.0, r = 1.0 - t, k = 5.0 / b.length;
      const double w[5] = {r * r * r * r, 4 * r * r * r * t, 6 * r * r * t * t, 4 * r * t * t * t,
                           t * t * t * t};
      for (int i = 0; i < kAxisCount; ++i) {
        double sum = 0;
        for (int j = 0; j < 5; ++j)
          sum += w[j] * (detail::quintic_point(b, j + 1)[i] - detail::quintic_point(b, j)[i]);
        d[i] = k * sum;
      }
      break;
    }
    case BlockKind::Marker:
      break;
  }
  return d;
}

/// d²p/ds² of block `b` at s. Any thread; real-time safe.
inline Pose curvature_at(const MotionBlock& b, double s) noexcept {
  Pose d;
  switch (b.kind) {
    case BlockKind::Line:
    case BlockKind::Marker:
      break;
    case BlockKind::Arc: {
      const double c = std::cos(b.omega * s), sn = std::sin(b.omega * s), w2 = b.omega * b.omega;
      for (int i = 0; i < kAxisCount; ++i) d[i] = w2 * (c * b.u[i] - sn * b.w[i]);
      break;
    }
    case BlockKind::Spiral: {
      // d²/dθ²: (1 + ρθ)·(cos θ·u − sin θ·w) + 2ρ·(cos θ·w + sin θ·u), times ω².
      const double th = b.omega * s, c = std::cos(th), sn = std::sin(th), a = 1.0 + b.spiral * th;
      const double w2 = b.omega * b.omega;
      for (int i = 0; i < kAxisCount; ++i) {
        d[i] = w2 * (a * (c * b.u[i] - sn * b.w[i]) + 2.0 * b.spiral * (c * b.w[i] + sn * b.u[i]));
      }
      break;
    }
    case BlockKind::Bezier: {
      const double t = b.length > 0 ? s / b.length : 0.0, r = 1.0 - t, k = 6.0 / (b.length * b.length);
      for (int i = 0; i < kAxisCount; ++i) {
        d[i] = k * (r * (b.w[i] - 2 * b.u[i] + b.base[i]) + t * (b.lin[i] - 2 * b.w[i] + b.u[i]));
      }
      break;
    }
    case BlockKind::Quintic: {
      // 20·Σ Δ²P_k·B³_k(t), per unit of s squared.
      const double t = b.length > 0 ? s / b.length : 0.0, r = 1.0 - t, k = 20.0 / (b.length * b.length);
      const double w[4] = {r * r * r, 3 * r * r * t, 3 * r * t * t, t * t * t};
      for (int i = 0; i < kAxisCount; ++i) {
        double sum = 0;
        for (int j = 0; j < 4; ++j) {
          sum += w[j] * (detail::quintic_point(b, j + 2)[i] - 2 * detail::quintic_point(b, j + 1)[i] +
                         detail::quintic_point(b, j)[i]);
        }
        d[i] = k * sum;
      }
      break;
    }
  }
  return d;
}

}  // namespace opencnc::traj
