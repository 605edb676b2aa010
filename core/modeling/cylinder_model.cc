#include "core/modeling/cylinder_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

namespace tubepick::internal {
namespace {

// A unit vector perpendicular to `a` (unit), chosen continuously enough for a local frame.
Eigen::Vector3d AnyPerpendicular(const Eigen::Vector3d& a) {
  const Eigen::Vector3d helper = std::abs(a.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return a.cross(helper).normalized();
}

}  // namespace

std::optional<CylinderModel> CylinderFromTwoPoints(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1,
                                                   const Eigen::Vector3d& p2, const Eigen::Vector3d& n2,
                                                   double min_sin_angle) {
  Eigen::Vector3d axis = n1.cross(n2);
  const double sin_angle = axis.norm();
  if (!(sin_angle >= min_sin_angle)) return std::nullopt;
  axis /= sin_angle;
  // In the plane perpendicular to the axis (which contains n1 and n2): p1 + s1·n1 = p2 + s2·n2.
  const Eigen::Vector3d d12 = p2 - p1;
  const Eigen::Vector3d d = d12 - d12.dot(axis) * axis;
  const double c = n1.dot(n2);
  const double det = c * c - 1.0;  // = −sin², non-zero here
  const double s2 = (n2.dot(d) - c * n1.dot(d)) / det;
  const double s1 = n1.dot(d) + c * s2;
  // Outward normals: the axis lies behind both surface points.
  if (!(s1 < 0.0 && s2 < 0.0)) return std::nullopt;
  CylinderModel model;
  model.point = p1 + s1 * n1;
  model.direction = axis;
  model.radius = 0.5 * (-s1 - s2);
  return model;
}

const Eigen::ArrayXf& CylinderDistance::Compute(const SoaCloud& cloud, const CylinderModel& model) {
  const Eigen::Index n = cloud.size();
  t_.resize(n);
  rx_.resize(n);
  ry_.resize(n);
  rz_.resize(n);
  dist_.resize(n);
  out_.resize(n);
  const Eigen::Vector3f c = model.point.cast<float>();
  const Eigen::Vector3f a = model.direction.cast<float>();
  const float r = static_cast<float>(model.radius);
  // Radial vector from the axis to each point.
  t_ = (cloud.x - c.x()) * a.x() + (cloud.y - c.y()) * a.y() + (cloud.z - c.z()) * a.z();
  rx_ = cloud.x - c.x() - t_ * a.x();
  ry_ = cloud.y - c.y() - t_ * a.y();
  rz_ = cloud.z - c.z() - t_ * a.z();
  dist_ = (rx_.square() + ry_.square() + rz_.square()).sqrt();
  // |cos| of the angle between normal and radial direction, then acos by Abramowitz & Stegun
  // 4.4.45 (|error| <= 6.7e-5 rad on [0, 1]).
  t_ = ((cloud.nx * rx_ + cloud.ny * ry_ + cloud.nz * rz_).abs() / dist_.max(1e-12f)).min(1.0f);
  out_ = (1.0f - t_).sqrt() * (1.5707288f + t_ * (-0.2121144f + t_ * (0.0742610f + t_ * -0.0187293f)));
  out_ = weight_ * out_ + (1.0f - weight_) * (dist_ - r).abs();
  return out_;
}

std::optional<CylinderModel> RefineCylinder(const std::vector<Eigen::Vector3d>& points,
                                            const CylinderModel& initial, int iterations) {
  const std::size_t n = points.size();
  if (n < 5) return std::nullopt;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(n);

  CylinderModel m = initial;
  m.direction.normalize();
  auto recentre = [&](CylinderModel* model) {
    model->point += (centroid - model->point).dot(model->direction) * model->direction;
  };
  recentre(&m);

  std::vector<double> residual(n), weight(n, 1.0), scratch(n);
  // Residuals distance-to-axis − radius; fills the Huber weights when `reweight`.
  auto evaluate = [&](const CylinderModel& model, bool reweight) {
    double cost = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d d = points[i] - model.point;
      residual[i] = (d - d.dot(model.direction) * model.direction).norm() - model.radius;
    }
    if (reweight) {
      for (std::size_t i = 0; i < n; ++i) scratch[i] = std::abs(residual[i]);
      const auto mid = scratch.begin() + static_cast<std::ptrdiff_t>(n / 2);
      std::nth_element(scratch.begin(), mid, scratch.end());
      const double sigma = std::max(1.4826 * *mid, 1e-5);
      const double huber = 1.345 * sigma;
      for (std::size_t i = 0; i < n; ++i) {
        const double a = std::abs(residual[i]);
        weight[i] = a <= huber ? 1.0 : huber / a;
      }
    }
    for (std::size_t i = 0; i < n; ++i) cost += weight[i] * residual[i] * residual[i];
    return cost;
  };

  double lambda = 1e-3;
  for (int it = 0; it < iterations; ++it) {
    double cost = evaluate(m, /*reweight=*/true);
    const Eigen::Vector3d u = AnyPerpendicular(m.direction);
    const Eigen::Vector3d v = m.direction.cross(u);
    // Parameters δ = (shift of the axis point along u, v; tilt of the axis toward u, v; radius).
    Eigen::Matrix<double, 5, 5> H = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> g = Eigen::Matrix<double, 5, 1>::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d d = points[i] - m.point;
      const double t = d.dot(m.direction);
      const Eigen::Vector3d q = d - t * m.direction;
      const double rho = q.norm();
      if (rho < 1e-9) continue;
      const Eigen::Vector3d q_hat = q / rho;
      const double qu = q_hat.dot(u), qv = q_hat.dot(v);
      Eigen::Matrix<double, 5, 1> J;
      J << -qu, -qv, -t * qu, -t * qv, -1.0;
      H.selfadjointView<Eigen::Lower>().rankUpdate(J, weight[i]);
      g += weight[i] * residual[i] * J;
    }
    H = H.selfadjointView<Eigen::Lower>();
    bool improved = false;
    for (int attempt = 0; attempt < 6 && !improved; ++attempt) {
      Eigen::Matrix<double, 5, 5> A = H;
      A.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
      const Eigen::Matrix<double, 5, 1> delta = A.ldlt().solve(-g);
      if (!delta.allFinite()) return std::nullopt;
      CylinderModel trial = m;
      trial.point += delta[0] * u + delta[1] * v;
      trial.direction = (m.direction + delta[2] * u + delta[3] * v).normalized();
      trial.radius += delta[4];
      recentre(&trial);
      const double trial_cost = evaluate(trial, /*reweight=*/false);
      if (trial_cost < cost) {
        const bool converged = delta.head<2>().norm() < 1e-8 && delta.segment<2>(2).norm() < 1e-8;
        m = trial;
        lambda = std::max(lambda * 0.1, 1e-9);
        improved = true;
        if (converged) it = iterations;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  if (!m.point.allFinite() || !m.direction.allFinite() || !std::isfinite(m.radius) || !(m.radius > 0.0)) {
    return std::nullopt;
  }
  return m;
}

}  // namespace tubepick::internal
