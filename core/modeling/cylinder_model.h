#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace tubepick::internal {

/// An infinite cylinder: the axis passes through `point` along the unit vector `direction`.
struct CylinderModel {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  double radius = 0.0;
};

/// The minimal-sample model from two surface points with outward unit normals: axis n1 × n2,
/// centre where the two normal lines cross in the plane perpendicular to the axis, radius the
/// mean distance of the two points to the axis. nullopt when the normals are nearly parallel
/// (|n1 × n2| < min_sin_angle) or the centre is not behind both points (a concave fit).
std::optional<CylinderModel> CylinderFromTwoPoints(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1,
                                                   const Eigen::Vector3d& p2, const Eigen::Vector3d& n2,
                                                   double min_sin_angle);

/// Points with normals in structure-of-arrays layout (vectorised inlier tests), as offsets from
/// `origin`.
struct SoaCloud {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::ArrayXf x, y, z, nx, ny, nz;

  Eigen::Index size() const { return x.size(); }
  Eigen::Vector3d point(Eigen::Index i) const { return Eigen::Vector3d(x[i], y[i], z[i]); }
  Eigen::Vector3d normal(Eigen::Index i) const { return Eigen::Vector3d(nx[i], ny[i], nz[i]); }
};

/// The pcl::SACMODEL_CYLINDER distance with normals, per point:
/// d = w·angle(n, radial direction) + (1 − w)·|distance to axis − radius|, the angle folded to
/// [0, π/2] (computed with a polynomial acos, error < 1e-4 rad). `model` is relative to
/// cloud.origin. Writes d into *distance (resized; scratch arrays are reused between calls).
class CylinderDistance {
 public:
  explicit CylinderDistance(double normal_distance_weight)
      : weight_(static_cast<float>(normal_distance_weight)) {}

  const Eigen::ArrayXf& Compute(const SoaCloud& cloud, const CylinderModel& model);

 private:
  float weight_;
  Eigen::ArrayXf t_, rx_, ry_, rz_, dist_, out_;
};

/// Least-squares refinement of a cylinder (axis point, direction, radius) on `points`:
/// Levenberg–Marquardt on the residuals distance-to-axis − radius, with Huber weights (scale
/// from the median absolute residual) so that stray inliers of a generous RANSAC threshold do
/// not pull the fit. The axis point returned is the projection of the points' centroid.
/// nullopt when the problem is degenerate (fewer than 5 points, non-finite result).
std::optional<CylinderModel> RefineCylinder(const std::vector<Eigen::Vector3d>& points,
                                            const CylinderModel& initial, int iterations = 10);

}  // namespace tubepick::internal
