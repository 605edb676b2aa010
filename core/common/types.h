#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tubepick {

/// A point cloud as plain data: xyz in metres, in the frame its owner names (usually Bin).
using Points = std::vector<Eigen::Vector3f>;

/// Points with unit surface normals (oriented towards the sensor) and PCL-style surface
/// curvature λ0/(λ0+λ1+λ2). All three vectors have the same size.
struct OrientedPoints {
  Points points;
  Points normals;
  std::vector<float> curvature;

  std::size_t size() const { return points.size(); }
};

/// A straight cylinder fitted to part of a tube. `start`/`end` are the centres of its bases
/// (the cylinder's endpoints), in the Bin frame; within a Tube they are ordered along the tube.
struct Cylinder {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
  double radius = 0.0;
  /// Index of the segment (region-growing cluster) whose points produced this cylinder.
  std::uint32_t segment_id = 0;
  /// Number of RANSAC inliers that support it.
  std::uint32_t inlier_count = 0;

  double length() const { return (end - start).norm(); }
  Eigen::Vector3d axis() const { return (end - start).normalized(); }
  Eigen::Vector3d centre() const { return 0.5 * (start + end); }
};

enum class Occlusion { kUnspecified = 0, kNone = 1, kWeak = 2, kStrong = 3 };

/// A virtual tube (thesis Def. 4.2.2): an ordered list of cylinders; consecutive cylinders are
/// linked by a joint from cylinders[i].end to cylinders[i+1].start.
struct Tube {
  std::uint32_t id = 0;
  std::vector<Cylinder> cylinders;
  Occlusion occlusion = Occlusion::kUnspecified;
  std::uint32_t occluded_joint_count = 0;

  /// Cylinder lengths plus joint lengths (Def. 4.2.6).
  double length() const {
    double sum = 0.0;
    for (std::size_t i = 0; i < cylinders.size(); ++i) {
      sum += cylinders[i].length();
      if (i + 1 < cylinders.size()) sum += (cylinders[i + 1].start - cylinders[i].end).norm();
    }
    return sum;
  }
};

}  // namespace tubepick
