#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/common/cell_config.h"
#include "core/common/types.h"

namespace tubepick {

struct PreparedCloud {
  /// Finite points, in metres, in the Bin frame.
  Points points_Bin;
  /// Points dropped because a coordinate was NaN or infinite.
  std::size_t dropped_non_finite = 0;
  /// Index in the input of each kept point; empty when nothing was dropped (identity).
  std::vector<std::uint32_t> source_index;
};

/// Scales `points_Sensor` from `unit` to metres, drops non-finite points and transforms the rest
/// into the bin frame with X_BinSensor.
/// @throws InvalidArgument when the input is empty or no finite point remains (the message says
///         how many points arrived and how many were non-finite).
PreparedCloud PrepareCloud(const Points& points_Sensor, LengthUnit unit,
                           const Eigen::Isometry3d& X_BinSensor);

}  // namespace tubepick
