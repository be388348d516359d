// SPDX-License-Identifier: GPL-3.0-or-later
// Gauss–Newton for the centre of a sphere of known radius: the residuals are the points' distances
// from the surface, their Jacobian the unit vectors from the points to the centre.
#include "opencnc/edm/sphere_fit.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace opencnc::edm {

namespace {

/// A step below this (mm) has converged: a thousandth of the nanometre the fit is good for.
constexpr double kStepTolerance = 1e-12;
constexpr int kMaxIterations = 50;

}  // namespace

std::optional<SphereFit> fit_sphere(std::span<const Vec3> points, double radius, const Vec3& guess) {
  const auto n = static_cast<Eigen::Index>(points.size());
  if (n < 3) return std::nullopt;
  Eigen::Vector3d c(guess[0], guess[1], guess[2]);
  Eigen::MatrixXd jacobian(n, 3);
  Eigen::VectorXd residual(n);
  SphereFit fit;
  for (fit.iterations = 1; fit.iterations <= kMaxIterations; ++fit.iterations) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto& p = points[static_cast<std::size_t>(i)];
      const Eigen::Vector3d d = Eigen::Vector3d(p[0], p[1], p[2]) - c;
      const double distance = d.norm();
      if (!(distance > 0)) return std::nullopt;
      residual(i) = distance - radius;
      jacobian.row(i) = -d.transpose() / distance;  // ∂|p − c|/∂c
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jacobian);
    if (qr.rank() < 3) return std::nullopt;
    const Eigen::Vector3d step = qr.solve(-residual);
    c += step;
    if (step.norm() < kStepTolerance) break;
  }
  if (fit.iterations > kMaxIterations) return std::nullopt;
  fit.centre = {c(0), c(1), c(2)};
  double sum = 0;
  for (const auto& p : points) {
    const double r = std::hypot(p[0] - c(0), p[1] - c(1), p[2] - c(2)) - radius;
    fit.residuals.push_back(r);
    sum += r * r;
    fit.max_residual = std::max(fit.max_residual, std::fabs(r));
  }
  fit.rms_residual = std::sqrt(sum / static_cast<double>(points.size()));
  return fit;
}

}  // namespace opencnc::edm
