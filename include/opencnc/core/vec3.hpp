// SPDX-License-Identifier: GPL-3.0-or-later
// Vec3 — the one three-vector of every layer (a point or a direction in X Y Z or U V W), and its
// arithmetic: sum, difference, scaling, dot and cross products, length.
#pragma once

#include <array>
#include <cmath>

#include "opencnc/core/axes.hpp"

namespace opencnc {

/// A point or a direction in three dimensions (mm unless the name says otherwise). Plain data;
/// real-time safe. A type of its own (not std::array) so that its operators are found from every
/// namespace.
struct Vec3 {
  std::array<double, 3> v{};

  constexpr double& operator[](int i) noexcept { return v[static_cast<std::size_t>(i)]; }
  constexpr double operator[](int i) const noexcept { return v[static_cast<std::size_t>(i)]; }
  constexpr bool operator==(const Vec3&) const noexcept = default;

  // A range of three doubles, as std::array is (loops, spans, serialisers).
  using value_type = double;
  constexpr double* data() noexcept { return v.data(); }
  constexpr const double* data() const noexcept { return v.data(); }
  constexpr double* begin() noexcept { return v.data(); }
  constexpr const double* begin() const noexcept { return v.data(); }
  constexpr double* end() noexcept { return v.data() + 3; }
  constexpr const double* end() const noexcept { return v.data() + 3; }
  static constexpr std::size_t size() noexcept { return 3; }
};

constexpr Vec3 operator+(const Vec3& a, const Vec3& b) noexcept {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
constexpr Vec3 operator-(const Vec3& a, const Vec3& b) noexcept {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
constexpr Vec3 operator*(double k, const Vec3& a) noexcept {
  return {k * a[0], k * a[1], k * a[2]};
}
constexpr double dot(const Vec3& a, const Vec3& b) noexcept {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
constexpr Vec3 cross(const Vec3& a, const Vec3& b) noexcept {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) noexcept {
  return std::sqrt(dot(a, a));
}

/// Three consecutive axes of a pose from `base` (0: X Y Z, 6: U V W).
constexpr Vec3 take3(const Pose& p, int base = 0) noexcept {
  return {p[base], p[base + 1], p[base + 2]};
}
/// Writes `x` into three consecutive axes of `p` from `base`.
constexpr void put3(Pose& p, int base, const Vec3& x) noexcept {
  p[base] = x[0];
  p[base + 1] = x[1];
  p[base + 2] = x[2];
}

}  // namespace opencnc
