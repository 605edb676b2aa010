// radius_outlier and statistical_outlier: neighbourhood-density filters (the semantics of
// pcl::RadiusOutlierRemoval on a hash grid, of pcl::StatisticalOutlierRemoval on a k-d tree).

#include <algorithm>
#include <cmath>

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "core/modeling/filters_internal.h"
#include "core/modeling/neighbour_grid.h"

namespace tubepick::internal {
namespace {

/// The cloud as PCL points; non-finite points stay in place (is_dense false) and the tree skips them.
pcl::PointCloud<pcl::PointXYZ>::Ptr ToPcl(const Points& points, std::size_t* finite_count) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(points.size());
  *finite_count = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    (*cloud)[i].getVector3fMap() = points[i];
    *finite_count += points[i].allFinite() ? 1 : 0;
  }
  cloud->width = static_cast<std::uint32_t>(points.size());
  cloud->height = 1;
  cloud->is_dense = *finite_count == points.size();
  return cloud;
}

std::vector<std::uint32_t> FiniteIndices(const Points& points) {
  std::vector<std::uint32_t> kept;
  kept.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].allFinite()) kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

}  // namespace

std::vector<std::uint32_t> RadiusOutlierFilter(const RadiusOutlierParams& params, const Points& points_Bin,
                                               const StopToken* stop) {
  if (params.min_neighbours == 0) return FiniteIndices(points_Bin);
  // A hash grid of cell size = radius (not PCL's FLANN tree, whose every query opens an OpenMP
  // region: 40 k queries cost more in thread wake-ups than in searching). A query's 3×3×3 block
  // then holds every point within the radius, so counting there answers it.
  const float radius = static_cast<float>(params.radius);
  const NeighbourGrid grid(points_Bin, radius);
  std::vector<std::uint32_t> kept;
  if (grid.size() <= params.min_neighbours) return kept;  // nobody can have enough neighbours
  // The point itself is its own nearest neighbour: it has min_neighbours others within the radius
  // exactly when min_neighbours + 1 points (itself included) are.
  const std::size_t k = params.min_neighbours + 1;
  const float r2 = radius * radius;  // as NeighbourGrid::Nearest rounds it
  // Rounding may put a point just past a cell face: far from the block's faces the block is exact,
  // nearer than this the ring search decides.
  const float safe_bound = radius * (1.0f + 1e-4f);
  std::vector<char> keep(points_Bin.size(), 0);
  auto count = [&](const NeighbourGrid::Block& block, const std::uint32_t* begin, const std::uint32_t* end,
                   std::vector<Neighbour>& neighbours) {
    for (const std::uint32_t* it = begin; it != end; ++it) {
      const Eigen::Vector3f& q = points_Bin[*it];
      if (!q.allFinite()) continue;
      if (block.Bound(q) < safe_bound) {
        grid.Nearest(q, k, radius, &neighbours);
        keep[*it] = neighbours.size() == k ? 1 : 0;
        continue;
      }
      std::size_t within = 0;
      for (std::size_t i = 0; i < block.size() && within < k; ++i) {
        const float dx = block.x[i] - q.x(), dy = block.y[i] - q.y(), dz = block.z[i] - q.z();
        within += dx * dx + dy * dy + dz * dz <= r2 ? 1 : 0;  // Nearest()'s rounding
      }
      keep[*it] = within >= k ? 1 : 0;
    }
  };
  grid.ForEachQueryBlock<std::vector<Neighbour>>(points_Bin, 1, stop, count);
  ThrowIfStopped(stop, "filter radius_outlier");
  kept.reserve(grid.size());
  for (std::uint32_t i = 0; i < points_Bin.size(); ++i) {
    if (keep[i] != 0) kept.push_back(i);
  }
  return kept;
}

std::vector<std::uint32_t> StatisticalOutlierFilter(const StatisticalOutlierParams& params,
                                                    const Points& points_Bin, const StopToken* stop) {
  std::size_t finite_count = 0;
  const auto cloud = ToPcl(points_Bin, &finite_count);
  if (finite_count < 3) return FiniteIndices(points_Bin);  // no meaningful statistics
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  // With fewer points than asked for, every point uses all the others.
  const int mean_k = static_cast<int>(std::min<std::size_t>(params.neighbours, finite_count - 1));
  pcl::Indices neighbours(mean_k + 1);
  std::vector<float> squared_distances(mean_k + 1);

  // Pass 1: mean distance of each point to its mean_k nearest neighbours (result 0 is itself).
  std::vector<double> mean_distance(points_Bin.size(), 0.0);
  double sum = 0.0, sum_squares = 0.0;
  for (std::size_t i = 0; i < points_Bin.size(); ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "filter statistical_outlier");
    if (!points_Bin[i].allFinite()) continue;
    const int found = tree.nearestKSearch((*cloud)[i], mean_k + 1, neighbours, squared_distances);
    double distance_sum = 0.0;
    for (int j = 1; j < found; ++j) distance_sum += std::sqrt(static_cast<double>(squared_distances[j]));
    mean_distance[i] = distance_sum / mean_k;
    sum += mean_distance[i];
    sum_squares += mean_distance[i] * mean_distance[i];
  }

  // Pass 2: keep d <= μ + mult·σ (thesis Eq. 4.1; σ with Bessel's correction, as PCL).
  const double n = static_cast<double>(finite_count);
  const double mean = sum / n;
  const double variance = std::max(0.0, (sum_squares - sum * sum / n) / (n - 1.0));
  const double threshold = mean + params.stddev_mult * std::sqrt(variance);
  std::vector<std::uint32_t> kept;
  kept.reserve(points_Bin.size());
  for (std::size_t i = 0; i < points_Bin.size(); ++i) {
    if (points_Bin[i].allFinite() && mean_distance[i] <= threshold)
      kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

}  // namespace tubepick::internal
