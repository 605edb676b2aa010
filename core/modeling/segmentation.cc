#include "core/modeling/segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/neighbour_grid.h"

namespace tubepick {
namespace {

using internal::Neighbour;
using internal::NeighbourGrid;

void Validate(const OrientedPoints& cloud, const SegmentationParams& params) {
  if (params.neighbours == 0) throw InvalidArgument("segmentation.neighbours: must be > 0, got 0");
  if (!(params.smoothness_threshold > 0.0) || !std::isfinite(params.smoothness_threshold)) {
    throw InvalidArgument("segmentation.smoothness_threshold: must be a positive angle in radians, got " +
                          std::to_string(params.smoothness_threshold));
  }
  if (params.min_cluster_size > params.max_cluster_size) {
    throw InvalidArgument("segmentation.min_cluster_size: " + std::to_string(params.min_cluster_size) +
                          " exceeds segmentation.max_cluster_size " +
                          std::to_string(params.max_cluster_size));
  }
  if (std::isnan(params.curvature_threshold)) throw InvalidArgument("segmentation.curvature_threshold: NaN");
  if (params.residual_test && std::isnan(params.residual_threshold)) {
    throw InvalidArgument("segmentation.residual_threshold: NaN");
  }
  if (cloud.normals.size() != cloud.points.size() || cloud.curvature.size() != cloud.points.size()) {
    throw InvalidArgument("segmentation: the cloud has " + std::to_string(cloud.points.size()) +
                          " points but " + std::to_string(cloud.normals.size()) + " normals and " +
                          std::to_string(cloud.curvature.size()) + " curvatures");
  }
}

}  // namespace

std::vector<Segment> SegmentRegions(const OrientedPoints& cloud, const SegmentationParams& params,
                                    const StopToken* stop, std::uint32_t threads) {
  Validate(cloud, params);

  // Points with a non-finite position, normal or curvature take no part (never in a segment).
  std::vector<std::uint32_t> original;  // compact index -> cloud index
  original.reserve(cloud.size());
  for (std::uint32_t i = 0; i < cloud.size(); ++i) {
    if (cloud.points[i].allFinite() && cloud.normals[i].allFinite() && std::isfinite(cloud.curvature[i])) {
      original.push_back(i);
    }
  }
  const std::size_t n = original.size();
  if (n == 0) return {};
  Points points(n), normals(n);
  std::vector<float> curvature(n);
  for (std::size_t c = 0; c < n; ++c) {
    points[c] = cloud.points[original[c]];
    normals[c] = cloud.normals[original[c]];
    curvature[c] = cloud.curvature[original[c]];
  }

  // k-nearest-neighbour graph (the point itself included, as pcl::RegionGrowing). A row's order
  // does not matter: a region is the closure of its seeds' accepted neighbours whatever the
  // order they are visited in. Cells of 1.5× the median k-th neighbour distance: a query's
  // 3×3×3 block then almost always holds its k nearest (~4% need the ring search).
  const std::size_t k = std::min<std::size_t>(params.neighbours, n);
  const NeighbourGrid grid(points, 1.5f * NeighbourGrid::SuggestCellSizeForNearest(points, k));
  std::vector<std::uint32_t> graph(n * k);
  std::vector<std::uint32_t> degree(n, 0);
  struct State {
    NeighbourGrid::NearestScratch scratch;
    std::vector<Neighbour> neighbours;
  };
  auto find_neighbours = [&](const NeighbourGrid::Block& block, const std::uint32_t* begin,
                             const std::uint32_t* end, State& state) {
    for (const std::uint32_t* it = begin; it != end; ++it) {
      grid.NearestInBlock(block, points[*it], k, std::numeric_limits<float>::infinity(), &state.scratch,
                          &state.neighbours);
      degree[*it] = static_cast<std::uint32_t>(state.neighbours.size());
      std::uint32_t* row = &graph[static_cast<std::size_t>(*it) * k];
      for (std::size_t m = 0; m < state.neighbours.size(); ++m) row[m] = state.neighbours[m].second;
    }
  };
  grid.ForEachQueryBlock<State>(points, threads, stop, find_neighbours);
  ThrowIfStopped(stop, "segmentation");

  // Seeds in order of increasing curvature, ties by index.
  std::vector<std::pair<float, std::uint32_t>> by_curvature(n);
  for (std::uint32_t c = 0; c < n; ++c) by_curvature[c] = {curvature[c], c};
  std::sort(by_curvature.begin(), by_curvature.end());

  const float cos_threshold = static_cast<float>(std::cos(params.smoothness_threshold));
  const float curvature_threshold = static_cast<float>(params.curvature_threshold);
  const float residual_threshold = static_cast<float>(params.residual_threshold);
  std::vector<std::int32_t> label(n, -1);
  std::vector<std::uint32_t> region_size;
  std::vector<std::uint32_t> seeds;  // FIFO: seeds[head..] are pending
  std::size_t popped = 0;
  for (const auto& [unused, initial] : by_curvature) {
    if (label[initial] != -1) continue;
    const std::int32_t region = static_cast<std::int32_t>(region_size.size());
    std::uint32_t size = 1;
    label[initial] = region;
    seeds.assign(1, initial);
    for (std::size_t head = 0; head < seeds.size(); ++head) {
      if (++popped % 4096 == 0) ThrowIfStopped(stop, "segmentation");
      const std::uint32_t seed = seeds[head];
      const Eigen::Vector3f& seed_point = points[seed];
      const Eigen::Vector3f& seed_normal = normals[seed];
      const std::uint32_t* row = &graph[static_cast<std::size_t>(seed) * k];
      for (std::uint32_t m = 0; m < degree[seed]; ++m) {
        const std::uint32_t nb = row[m];
        if (label[nb] != -1) continue;
        // Smoothness: the angle between the current seed's normal and the neighbour's.
        if (std::abs(seed_normal.dot(normals[nb])) < cos_threshold) continue;
        label[nb] = region;
        ++size;
        bool is_seed = curvature[nb] <= curvature_threshold;
        if (is_seed && params.residual_test) {
          is_seed = std::abs(seed_normal.dot(seed_point - points[nb])) <= residual_threshold;
        }
        if (is_seed) seeds.push_back(nb);
      }
    }
    region_size.push_back(size);
  }

  // Regions within the size limits, in the order they were grown; indices ascending.
  std::vector<std::int32_t> segment_of_region(region_size.size(), -1);
  std::vector<Segment> segments;
  for (std::size_t r = 0; r < region_size.size(); ++r) {
    if (region_size[r] < params.min_cluster_size || region_size[r] > params.max_cluster_size) continue;
    segment_of_region[r] = static_cast<std::int32_t>(segments.size());
    segments.emplace_back();
    segments.back().reserve(region_size[r]);
  }
  for (std::size_t c = 0; c < n; ++c) {
    const std::int32_t s = segment_of_region[static_cast<std::size_t>(label[c])];
    if (s >= 0) segments[static_cast<std::size_t>(s)].push_back(original[c]);
  }
  return segments;
}

}  // namespace tubepick
