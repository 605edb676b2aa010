#include "viewer/view_cloud.h"

#include <cmath>

#include <fmt/core.h>

#include "core/common/errors.h"

namespace tubepick::viewer {
namespace {

template <typename PointAt>
ViewCloud Thin(std::size_t size, const PointAt& point_at, LengthUnit unit,
               const Eigen::Isometry3d& X_BinSensor, std::size_t max_points) {
  if (max_points == 0) throw InvalidArgument("view: max_points must be at least 1");
  ViewCloud cloud;
  cloud.total_points = size;
  const std::size_t stride = std::max<std::size_t>(1, (size + max_points - 1) / max_points);
  const Eigen::Affine3f X = (X_BinSensor * Eigen::Scaling(MetresPer(unit))).cast<float>();
  cloud.xyz_Bin.reserve(3 * std::min(size, max_points));
  for (std::size_t i = 0; i < size; i += stride) {
    const Eigen::Vector3f p = point_at(i);
    if (!p.allFinite()) continue;
    const Eigen::Vector3f q = X * p;
    cloud.xyz_Bin.insert(cloud.xyz_Bin.end(), {q.x(), q.y(), q.z()});
  }
  return cloud;
}

}  // namespace

ViewCloud ThinToBin(const PackedXyz& xyz_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                    std::size_t max_points) {
  return Thin(
      xyz_Sensor.size(), [&](std::size_t i) { return xyz_Sensor.Point(i); }, unit, X_BinSensor, max_points);
}

ViewCloud ThinToBin(const Points& points_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                    std::size_t max_points) {
  return Thin(
      points_Sensor.size(), [&](std::size_t i) { return points_Sensor[i]; }, unit, X_BinSensor, max_points);
}

}  // namespace tubepick::viewer
