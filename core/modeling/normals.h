#pragma once

#include <cstdint>

#include "core/common/stop_token.h"
#include "core/common/types.h"

namespace tubepick {

/// Which cloud supplies the neighbours of each point (thesis §4.3.1 uses the raw cloud for more
/// accurate normals; §5.3.4 notes its cost).
enum class SearchSurface { kRaw, kFiltered };

struct NormalParams {
  /// Neighbourhood radius, metres (Table 4.2: 0.5 cm).
  double radius = 0.005;
  /// Cap on neighbours used per point (nearest first); 0 = all within the radius.
  std::uint32_t max_neighbours = 0;
  SearchSurface search_surface = SearchSurface::kFiltered;
};

/// Estimates a unit normal and the curvature λ0/(λ0+λ1+λ2) at each query point from the
/// covariance of its neighbours in `surface` within params.radius (pcl::NormalEstimationOMP).
/// Normals are flipped to face `viewpoint_Bin` (the sensor origin). Points with fewer than 3
/// neighbours get NaN normal and curvature (the caller drops them). Runs on
/// ResolveThreads(threads) OpenMP threads; the result does not depend on the thread count.
/// @throws InvalidArgument for radius <= 0.
OrientedPoints EstimateNormals(const Points& query_Bin, const Points& surface_Bin, const NormalParams& params,
                               const Eigen::Vector3f& viewpoint_Bin, const StopToken* stop = nullptr,
                               std::uint32_t threads = 0);

}  // namespace tubepick
