#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/stop_token.h"
#include "core/common/types.h"

namespace tubepick {

/// Keeps the points inside an axis-aligned box of the bin frame (thesis §5.2.1, pcl::CropBox).
struct CropBoxParams {
  /// When true the box is the bin's interior: x, y shrunk by `inset_xy` from the walls, z from
  /// `min_z` up to the wall height plus `above_walls`. When false, `min`/`max` are used.
  bool from_bin = true;
  /// Inset from the inner walls, metres (removes the wall points).
  double inset_xy = 0.005;
  /// Lowest z kept, metres above the floor (removes the floor points).
  double min_z = 0.004;
  /// How far above the wall top points are kept, metres (tubes lean over walls).
  double above_walls = 0.30;
  /// Explicit box corners in the bin frame, used when from_bin is false.
  Eigen::Vector3d min{-0.4, -0.3, 0.004};
  Eigen::Vector3d max{0.4, 0.3, 0.5};
};

enum class Axis { kX = 0, kY = 1, kZ = 2 };
enum class FilterFrame { kBin, kSensor };

/// Keeps points whose coordinate along one axis lies in [min, max] (pcl::PassThrough). The
/// thesis' depth filter is axis z in the sensor frame, [0.1, 1.0] m.
struct PassThroughParams {
  Axis axis = Axis::kZ;
  FilterFrame frame = FilterFrame::kSensor;
  double min = 0.1;
  double max = 1.0;
};

/// One point per occupied voxel: the point nearest to the voxel's centroid (points are kept,
/// never moved, so normals computed earlier stay valid).
struct VoxelGridParams {
  /// Voxel edge, metres.
  double leaf_size = 0.003;
};

/// Keeps `count` points chosen uniformly at random (seeded); all points when fewer.
struct RandomSampleParams {
  std::uint32_t count = 100000;
};

/// Removes points with fewer than `min_neighbours` other points within `radius`
/// (pcl::RadiusOutlierRemoval).
struct RadiusOutlierParams {
  double radius = 0.007;
  std::uint32_t min_neighbours = 10;
};

/// Removes points whose mean distance to their `neighbours` nearest neighbours exceeds
/// μ + stddev_mult·σ over the cloud (pcl::StatisticalOutlierRemoval, thesis Eq. 4.1).
struct StatisticalOutlierParams {
  std::uint32_t neighbours = 100;
  double stddev_mult = 3.0;
};

/// Removes the largest plane roughly perpendicular to `axis` found by RANSAC with normals
/// (pcl::SACSegmentationFromNormals, SACMODEL_NORMAL_PARALLEL_PLANE). Needs normals.
struct PlaneRemovalParams {
  /// Maximum inlier distance (weighted with the normal term), metres.
  double distance_threshold = 0.015;
  /// Weight of the angular term in the inlier distance, in [0, 1].
  double normal_distance_weight = 0.07;
  /// Plane normal the model must be near, bin frame.
  Eigen::Vector3d axis{0.0, 0.0, 1.0};
  /// Maximum angle between the plane normal and `axis`, radians.
  double eps_angle = 0.14;
  std::uint32_t max_iterations = 1000;
  /// Desired probability of drawing one outlier-free sample (stops RANSAC early).
  double probability = 0.2;
  /// The plane is removed only if it has at least this many inliers.
  std::uint32_t min_inliers = 1000;
};

/// One step of the ordered, configurable filter pipeline.
using FilterStep = std::variant<CropBoxParams, PassThroughParams, VoxelGridParams, RandomSampleParams,
                                RadiusOutlierParams, StatisticalOutlierParams, PlaneRemovalParams>;

/// YAML / log name of a step: crop_box, pass_through, voxel_grid, random_sample,
/// radius_outlier, statistical_outlier, plane_removal.
std::string FilterName(const FilterStep& step);

/// True for steps that need normals (plane_removal).
bool FilterNeedsNormals(const FilterStep& step);

/// What a filter may look at besides the points.
struct FilterContext {
  Eigen::Isometry3d X_BinSensor = Eigen::Isometry3d::Identity();
  BinConfig bin;
};

/// Applies one step to `points_Bin` (with `normals` when already estimated; must be non-null for
/// steps where FilterNeedsNormals). Returns the indices of the kept points in increasing order.
/// `seed` drives every random choice: same input + seed ⇒ same output.
/// @throws InvalidArgument for invalid parameters (naming them) or missing normals.
std::vector<std::uint32_t> ApplyFilter(const FilterStep& step, const Points& points_Bin,
                                       const Points* normals, const FilterContext& context,
                                       std::uint64_t seed, const StopToken* stop = nullptr);

/// The box a crop_box step keeps, in the bin frame, as float corners (the points' precision).
/// @throws InvalidArgument when from_bin makes it empty (the message names the bin and the params).
std::pair<Eigen::Vector3f, Eigen::Vector3f> CropBoxBounds(const CropBoxParams& params, const BinConfig& bin);

/// True when p_Bin lies in the box [lo, hi] (inclusive); NaN fails every comparison.
inline bool InCropBox(const Eigen::Vector3f& p_Bin, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  return p_Bin.x() >= lo.x() && p_Bin.x() <= hi.x() && p_Bin.y() >= lo.y() && p_Bin.y() <= hi.y() &&
         p_Bin.z() >= lo.z() && p_Bin.z() <= hi.z();
}

/// Checks a step's parameters. @throws InvalidArgument naming `key` and the bad value.
void ValidateFilter(const FilterStep& step, const std::string& key);

}  // namespace tubepick
