#pragma once

#include <cstdint>
#include <vector>

#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/modeling/segmentation.h"

namespace tubepick {

/// Iterative RANSAC cylinder fitting per segment (thesis §4.3.3, Table 4.3).
struct CylinderFitParams {
  /// Minimum inliers to accept a cylinder; fitting on a segment stops below it.
  std::uint32_t min_inliers = 100;
  double min_radius = 0.007;
  double max_radius = 0.015;
  /// Maximum inlier distance d = w·angle + (1−w)·|dist_to_axis − r|, as PCL (metres/radians).
  double distance_threshold = 0.02;
  /// w above, in [0, 1].
  double normal_distance_weight = 0.07;
  std::uint32_t max_iterations = 1000;
  /// Stop RANSAC once this probability of having drawn an outlier-free sample is reached.
  double probability = 0.99;
  /// ε_Δl: the overlap safety zone extends the cylinder by this at both bases, metres.
  double safety_length = 0.01;
  /// ε_r: radius of the overlap safety zone, metres.
  double safety_radius = 0.02;
  /// Refine axis and radius of the best model by least squares on its inliers.
  bool refine = true;
};

struct FittedCylinder {
  /// Endpoints from the inlier extent along the axis; segment_id and inlier_count filled in.
  Cylinder cylinder;
  /// Indices into the cloud of its inliers.
  std::vector<std::uint32_t> inliers;
};

/// Fits cylinders to one segment until fewer than min_inliers points remain (Algorithm 1,
/// lines 5–8). After each cylinder its inliers and the remaining points inside the safety zone
/// are removed. Random draws come only from `seed`: same cloud, segment and seed ⇒ same
/// cylinders (callers derive per-segment seeds so results do not depend on thread count).
/// @throws InvalidArgument for inconsistent parameters (min_radius > max_radius, ...).
std::vector<FittedCylinder> FitCylinders(const OrientedPoints& cloud, const Segment& segment,
                                         std::uint32_t segment_id, const CylinderFitParams& params,
                                         std::uint64_t seed, const StopToken* stop = nullptr);

}  // namespace tubepick
