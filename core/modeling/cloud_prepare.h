#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "core/common/cell_config.h"
#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/modeling/cloud_plausibility.h"

namespace tubepick {

/// A cloud in its wire form (tubepick.v1.PointCloud.xyz): packed little-endian float32 x, y, z,
/// 12 bytes a point, read in place (not owned). @pre bytes.size() is a multiple of 12.
struct PackedXyz {
  std::string_view bytes;

  std::size_t size() const { return bytes.size() / 12; }
  /// Point i, whatever the host's byte order. @pre i < size()
  Eigen::Vector3f Point(std::size_t i) const;
};

/// Which raw points (bin frame, metres) a later collision test needs kept: those with z >= min_z
/// whose |x| <= half_xy.x() and |y| <= half_xy.y(), and every point with z >= any_xy_above_z.
struct RawRegion {
  double min_z = -std::numeric_limits<double>::infinity();
  Eigen::Vector2d half_xy = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  double any_xy_above_z = -std::numeric_limits<double>::infinity();

  /// Every point (the default).
  static RawRegion All() { return {}; }
  /// No point.
  static RawRegion None() {
    RawRegion r;
    r.min_z = r.any_xy_above_z = std::numeric_limits<double>::infinity();
    return r;
  }
  bool KeepsAll() const { return *this == All(); }
  bool KeepsNone() const { return *this == None(); }
  /// True when every point `other` keeps, this keeps too (compared field by field).
  bool Covers(const RawRegion& other) const {
    return other.min_z >= min_z && (other.half_xy.array() <= half_xy.array()).all() &&
           other.any_xy_above_z >= any_xy_above_z;
  }
  bool operator==(const RawRegion& other) const {
    return min_z == other.min_z && half_xy == other.half_xy && any_xy_above_z == other.any_xy_above_z;
  }
};

/// What the one pass over the input keeps besides the plausibility evidence.
struct PrepareSpec {
  /// Bin-frame box (inclusive, float) of the working set: a leading crop_box step of the filter
  /// chain, applied in the same pass. nullopt: the working set is every finite point.
  std::optional<std::pair<Eigen::Vector3f, Eigen::Vector3f>> crop_Bin;
  /// Finite points in this region are also kept as `raw_Bin`.
  RawRegion raw_region_Bin;
  BinConfig bin;
  PlausibilityParams plausibility;
};

struct PreparedCloud {
  std::uint64_t input_points = 0;
  /// Points dropped because a coordinate was NaN or infinite (before or after the transform).
  std::uint64_t dropped_non_finite = 0;
  /// The finite points inside spec.crop_Bin, in metres, bin frame, in input order.
  Points working_Bin;
  /// Index in the input of each working point.
  std::vector<std::uint32_t> working_source_index;
  /// The finite points in spec.raw_region_Bin, in input order.
  Points raw_Bin;
  /// How every finite point fits the cell (PlausibilityTally).
  CloudPlausibility plausibility;
};

/// One pass over the scanner's cloud: scales from `unit` to metres, maps into the bin frame with
/// X_BinSensor, drops non-finite points, measures the cloud against the cell and keeps the working
/// set (and raw points) `spec` asks for. No full-size copy is made unless spec asks for all raw
/// points. Checks nothing but emptiness: RequirePlausible decides on the evidence.
/// @throws InvalidArgument when the input is empty or no finite point remains (the message says
///         how many points arrived and how many were non-finite).
/// @throws Cancelled when `stop` fires.
PreparedCloud PrepareCloud(const Points& points_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                           const PrepareSpec& spec, const StopToken* stop = nullptr);
PreparedCloud PrepareCloud(PackedXyz xyz_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                           const PrepareSpec& spec, const StopToken* stop = nullptr);

}  // namespace tubepick
