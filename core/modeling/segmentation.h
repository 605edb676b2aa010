#pragma once

#include <cstdint>
#include <vector>

#include "core/common/stop_token.h"
#include "core/common/types.h"

namespace tubepick {

/// Region growing (Rabbani et al. 2006, pcl::RegionGrowing), Table 4.3.
struct SegmentationParams {
  /// Clusters smaller than this are discarded.
  std::uint32_t min_cluster_size = 100;
  std::uint32_t max_cluster_size = 1000000;
  /// k of the k-nearest-neighbour graph (the point itself counted, as pcl::RegionGrowing).
  std::uint32_t neighbours = 77;
  /// Maximum angle between neighbouring normals to grow a region, radians (Table 4.3: 5°).
  double smoothness_threshold = 5.0 * 3.14159265358979323846 / 180.0;
  /// Points with curvature below this become seeds of the region they join.
  double curvature_threshold = 0.2;
  /// When true, a neighbour farther than residual_threshold (metres) from the current seed's
  /// tangent plane still joins the region but does not become a seed (pcl::RegionGrowing).
  bool residual_test = false;
  double residual_threshold = 10.0;
};

/// A segment: indices into the segmented cloud.
using Segment = std::vector<std::uint32_t>;

/// Splits the cloud into smooth regions. Deterministic: seeds are taken in order of increasing
/// curvature (ties by index). Segments are returned in the order they were grown, indices
/// ascending within a segment; each index appears in at most one segment. Points with a
/// non-finite position, normal or curvature are in no segment. The k-NN graph is built on
/// ResolveThreads(threads) OpenMP threads; the result does not depend on the thread count.
/// @throws InvalidArgument for neighbours == 0, a non-positive smoothness threshold,
/// min_cluster_size > max_cluster_size, or normals/curvature sizes that differ from the points'.
std::vector<Segment> SegmentRegions(const OrientedPoints& cloud, const SegmentationParams& params,
                                    const StopToken* stop = nullptr, std::uint32_t threads = 0);

}  // namespace tubepick
