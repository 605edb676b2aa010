#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "core/modeling/cloud_prepare.h"

namespace tubepick::viewer {

/// The cloud a page draws: at most `max_points` finite points of the scan, bin frame, metres.
struct ViewCloud {
  /// x, y, z of each kept point.
  std::vector<float> xyz_Bin;
  /// Points of the scan, finite or not, before thinning.
  std::uint64_t total_points = 0;

  std::size_t size() const { return xyz_Bin.size() / 3; }
};

/// Every k-th point of a scan (k = ceil(size / max_points)), the same points for the same scan,
/// moved into the bin frame (`unit` → metres, then X_BinSensor); non-finite points are skipped.
/// Reads only the kept points (a twelfth of a 2.3 M-point scan at 200 k), whatever the scan's size.
/// @throws InvalidArgument when max_points is 0.
ViewCloud ThinToBin(const PackedXyz& xyz_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                    std::size_t max_points);
ViewCloud ThinToBin(const Points& points_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                    std::size_t max_points);

}  // namespace tubepick::viewer
