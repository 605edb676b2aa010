#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/types.h"

namespace tubepick::testing {

/// A tube as a centreline polyline with a constant radius (capsule chain), bin frame.
struct SyntheticTube {
  std::vector<Eigen::Vector3d> centreline;
  double radius = 0.0125;

  double length() const;
};

struct SyntheticCloudParams {
  Eigen::Isometry3d X_BinSensor = SensorConfig::DefaultX_BinSensor();
  /// Angular size of one sensor pixel, radians (0.0005 ≈ 0.55 mm at 1.1 m, Zivid-class).
  double pixel_angle = 0.0005;
  /// Half field of view covered, radians, in optical x and y.
  double half_fov_x = 0.40;
  double half_fov_y = 0.28;
  /// Gaussian noise along the viewing ray, metres (σ).
  double depth_noise = 0.0003;
  /// Add the floor plane z = 0 over floor_size (x, y) centred at the bin origin.
  bool floor = true;
  Eigen::Vector2d floor_size{0.80, 0.60};
  std::uint64_t seed = 1;
};

struct SyntheticCloud {
  /// What a scanner returns: sensor optical frame, metres.
  Points points_Sensor;
  /// Per point: index of the tube it lies on, or −1 for the floor.
  std::vector<int> label;
};

/// Renders tubes (and optionally the floor) as a scanner at X_BinSensor sees them: one ray per
/// pixel, nearest hit kept (so occluded parts are missing), depth noise added. Analytic and
/// deterministic for a seed.
SyntheticCloud RenderSyntheticCloud(const std::vector<SyntheticTube>& tubes,
                                    const SyntheticCloudParams& params);

/// A straight tube from `a` to `b` (two-point centreline).
SyntheticTube StraightTube(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius = 0.0125);

/// A tube lying on the floor (centreline at z = radius + lift) through the given xy vertices.
SyntheticTube FloorTube(const std::vector<Eigen::Vector2d>& xy, double radius = 0.0125, double lift = 0.0);

}  // namespace tubepick::testing
