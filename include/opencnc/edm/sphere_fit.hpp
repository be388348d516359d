// SPDX-License-Identifier: GPL-3.0-or-later
// The least-squares centre of a sphere of known radius through probed points (electrode setting).
#pragma once

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "opencnc/core/vec3.hpp"

namespace opencnc::edm {

/// The centre that best fits the points, with the residuals |p − centre| − radius, mm.
struct SphereFit {
  Vec3 centre{};
  std::vector<double> residuals;  ///< per point, in the order given
  double rms_residual = 0;
  double max_residual = 0;  ///< largest |residual|
  int iterations = 0;
};

/// The centre c minimising Σ (|p_i − c| − radius)² (the geometric fit, not the algebraic one: its
/// residuals are distances), by Gauss–Newton from `guess` with a QR solve of each step (Eigen).
/// Nothing when there are fewer than three points, when a point sits on the centre, when the
/// points do not fix the centre (all on one line through it, say) or when it does not converge in
/// 50 steps. Any thread; not real-time.
std::optional<SphereFit> fit_sphere(std::span<const Vec3> points, double radius, const Vec3& guess);

}  // namespace opencnc::edm
