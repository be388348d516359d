// SPDX-License-Identifier: GPL-3.0-or-later
// B's axis of rotation fitted to the sphere's centres at several B angles: the plane's normal,
// the circle's centre, the electrode's offsets taken out.
#include "opencnc/edm/b_axis_fit.hpp"
#include "opencnc/core/vec3.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "opencnc/machine/rotary_axis.hpp"

namespace opencnc::edm {

namespace {

constexpr double kRad = std::numbers::pi / 180;

Eigen::Vector3d vec(const Vec3& p) {
  return {p[0], p[1], p[2]};
}

Vec3 point(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

/// The circle of least squares through 2-D points: the algebraic (Kåsa) fit as the start, then
/// Gauss–Newton on the distances. Nothing when the points fix no circle.
std::optional<Eigen::Vector3d> fit_circle(const std::vector<Eigen::Vector2d>& p) {
  const auto n = static_cast<Eigen::Index>(p.size());
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d& q = p[static_cast<std::size_t>(i)];
    a.row(i) << 2 * q.x(), 2 * q.y(), 1;
    b(i) = q.squaredNorm();
  }
  const auto qr = a.colPivHouseholderQr();
  if (qr.rank() < 3) return std::nullopt;
  const Eigen::Vector3d s = qr.solve(b);
  Eigen::Vector3d c(s(0), s(1), std::sqrt(std::max(0.0, s(2) + s(0) * s(0) + s(1) * s(1))));
  for (int step = 0; step < 20; ++step) {
    Eigen::MatrixXd j(n, 3);
    Eigen::VectorXd r(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector2d d = p[static_cast<std::size_t>(i)] - c.head<2>();
      const double length = d.norm();
      if (length == 0) return std::nullopt;
      r(i) = length - c(2);
      j.row(i) << -d.x() / length, -d.y() / length, -1;
    }
    const Eigen::Vector3d delta = j.colPivHouseholderQr().solve(-r);
    c += delta;
    if (delta.norm() < 1e-12) break;
  }
  return c;
}

}  // namespace

Vec3 sphere_centre_at(const config::ReferenceSphereProfile& sphere, double b_deg) {
  if (!sphere.has_b_axis || b_deg == sphere.b_deg) return sphere.position;
  const Vec3 on_axis{sphere.b_axis[0], sphere.position[1], sphere.b_axis[1]};
  return machine::rotate_about(sphere.position, on_axis, sphere.b_axis_direction,
                               (b_deg - sphere.b_deg) * kRad);
}

std::optional<BAxisFit> fit_b_axis(std::span<const double> angles_deg, std::span<const Vec3> centres,
                                   const config::ReferenceSphereProfile& sphere) {
  const std::size_t n = std::min(angles_deg.size(), centres.size());
  std::vector<double> distinct(angles_deg.begin(), angles_deg.begin() + static_cast<std::ptrdiff_t>(n));
  std::sort(distinct.begin(), distinct.end());
  if (std::unique(distinct.begin(), distinct.end()) - distinct.begin() < 3) return std::nullopt;
  // The plane: its normal is the covariance's direction of least spread.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k) mean += vec(centres[k]);
  mean /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < n; ++k) cov += (vec(centres[k]) - mean) * (vec(centres[k]) - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.eigenvalues()(1) <= 1e-12 * std::max(1.0, eig.eigenvalues()(2))) return std::nullopt;  // a line
  Eigen::Vector3d normal = eig.eigenvectors().col(0);
  const Eigen::Vector3d u = eig.eigenvectors().col(2), v = normal.cross(u);
  std::vector<Eigen::Vector2d> flat;
  for (std::size_t k = 0; k < n; ++k)
    flat.emplace_back((vec(centres[k]) - mean).dot(u), (vec(centres[k]) - mean).dot(v));
  const std::optional<Eigen::Vector3d> circle = fit_circle(flat);
  if (!circle || !((*circle)(2) > 0)) return std::nullopt;
  Eigen::Vector3d centre = mean + (*circle)(0) * u + (*circle)(1) * v;
  // B turns right-handed about the direction: the way the centres go round as B grows, seen
  // from the two angles whose turn between them is farthest from 0° and 180° (its sense is surest).
  std::size_t from = 0, to = 1;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = i + 1; k < n; ++k)
      if (std::fabs(std::sin((angles_deg[k] - angles_deg[i]) * kRad)) >
          std::fabs(std::sin((angles_deg[to] - angles_deg[from]) * kRad))) {
        from = i;
        to = k;
      }
  const Eigen::Vector3d a = vec(centres[from]) - centre, b = vec(centres[to]) - centre;
  if (a.cross(b).dot(normal) * std::sin((angles_deg[to] - angles_deg[from]) * kRad) < 0) normal = -normal;
  if (std::fabs(normal.y()) < 1e-6) return std::nullopt;  // the axis does not cross the sphere's plane
  // Each centre turned back to b: their mean is the sphere plus the electrode's offsets there.
  Eigen::Vector3d at_b = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k)
    at_b += vec(machine::rotate_about(centres[k], point(centre), point(normal),
                                      (sphere.b_deg - angles_deg[k]) * kRad));
  at_b /= static_cast<double>(n);
  const Eigen::Vector3d offsets = at_b - vec(sphere.position);
  BAxisFit fit;
  fit.radius_mm = (*circle)(2);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 predicted = machine::rotate_about(point(at_b), point(centre), point(normal),
                                                 (angles_deg[k] - sphere.b_deg) * kRad);
    const double r = (vec(predicted) - vec(centres[k])).norm();
    fit.residuals_mm.push_back(r);
    fit.rms_residual_mm += r * r;
    fit.max_residual_mm = std::max(fit.max_residual_mm, r);
  }
  fit.rms_residual_mm = std::sqrt(fit.rms_residual_mm / static_cast<double>(n));
  // The axis of the sphere itself, crossing the plane of its centre.
  const Eigen::Vector3d on_axis = centre - offsets;
  const double t = (sphere.position[1] - on_axis.y()) / normal.y();
  fit.axis.crossing = {on_axis.x() + t * normal.x(), on_axis.z() + t * normal.z()};
  fit.axis.direction = point(normal);
  return fit;
}

}  // namespace opencnc::edm
