// SPDX-License-Identifier: GPL-3.0-or-later
// Small vector arithmetic on nine-axis poses, for the planner's geometry.
#pragma once

#include <cmath>

#include "opencnc/core/axes.hpp"

namespace opencnc::plan::detail {

inline Pose operator+(const Pose& a, const Pose& b) noexcept {
  Pose r;
  for (int i = 0; i < kAxisCount; ++i) r[i] = a[i] + b[i];
  return r;
}
inline Pose operator-(const Pose& a, const Pose& b) noexcept {
  Pose r;
  for (int i = 0; i < kAxisCount; ++i) r[i] = a[i] - b[i];
  return r;
}
inline Pose operator*(double k, const Pose& a) noexcept {
  Pose r;
  for (int i = 0; i < kAxisCount; ++i) r[i] = k * a[i];
  return r;
}
inline double dot(const Pose& a, const Pose& b) noexcept {
  double s = 0;
  for (int i = 0; i < kAxisCount; ++i) s += a[i] * b[i];
  return s;
}
inline double norm(const Pose& a) noexcept {
  return std::sqrt(dot(a, a));
}

/// Angle between two unit vectors, accurate for small angles.
inline double angle_between(const Pose& a, const Pose& b) noexcept {
  const double h = 0.5 * norm(b - a);
  return 2.0 * std::asin(h < 1.0 ? h : 1.0);
}

}  // namespace opencnc::plan::detail
