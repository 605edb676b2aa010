#include "core/modeling/neighbour_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace tubepick::internal {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The k nearest of `points` to q within max_radius by (squared distance, index), computed with
// the grid's rounding.
std::vector<std::uint32_t> BruteForce(const Points& points, const Eigen::Vector3f& q, std::size_t k,
                                      float max_radius) {
  std::vector<Neighbour> all;
  for (std::uint32_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const float dx = points[i].x() - q.x(), dy = points[i].y() - q.y(), dz = points[i].z() - q.z();
    const float d2 = dx * dx + dy * dy + dz * dz;
    if (d2 <= max_radius * max_radius) all.emplace_back(d2, i);
  }
  std::sort(all.begin(), all.end());
  if (all.size() > k) all.resize(k);
  std::vector<std::uint32_t> indices;
  for (const Neighbour& n : all) indices.push_back(n.second);
  std::sort(indices.begin(), indices.end());
  return indices;
}

std::vector<std::uint32_t> Indices(const std::vector<Neighbour>& neighbours) {
  std::vector<std::uint32_t> indices;
  for (const Neighbour& n : neighbours) indices.push_back(n.second);
  std::sort(indices.begin(), indices.end());
  return indices;
}

// Surfaces, volumes, clusters with far outliers, exact duplicates, and a non-finite point.
Points MakeCloud(int kind, std::mt19937_64& rng) {
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  Points points;
  for (int i = 0; i < 400; ++i) {
    Eigen::Vector3f p(u(rng), u(rng), u(rng));
    if (kind == 0) p.z() = 0.002f * std::sin(100.0f * p.x());
    if (kind == 2) p *= (i % 10 == 0) ? 5.0f : 0.3f;
    if (kind == 3 && i % 5 == 0 && !points.empty()) p = points[static_cast<std::size_t>(i / 2)];
    points.push_back(p);
  }
  points.push_back(Eigen::Vector3f(1.0f, -1.0f, 2.0f));
  points.push_back(Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
  return points;
}

TEST(NeighbourGrid, NearestMatchesBruteForce) {
  std::mt19937_64 rng(7);
  for (int kind = 0; kind < 4; ++kind) {
    const Points points = MakeCloud(kind, rng);
    for (const float cell : {0.001f, 0.01f}) {
      const NeighbourGrid grid(points, cell);
      EXPECT_EQ(grid.size(), points.size() - 1);  // the NaN point is left out
      for (const std::size_t k : {1u, 7u, 30u}) {
        for (const float max_radius : {0.006f, kInf}) {
          Points queries(points.begin(), points.end() - 1);
          queries.push_back(Eigen::Vector3f(0.3f, 2.0f, -0.1f));  // outside the grid
          std::vector<std::vector<std::uint32_t>> in_block(queries.size());
          struct State {
            NeighbourGrid::NearestScratch scratch;
            std::vector<Neighbour> out;
          };
          grid.ForEachQueryBlock<State>(queries, nullptr,
                                        [&](const NeighbourGrid::Block& block, const std::uint32_t* begin,
                                            const std::uint32_t* end, State& state) {
                                          for (const std::uint32_t* it = begin; it != end; ++it) {
                                            grid.NearestInBlock(block, queries[*it], k, max_radius,
                                                                &state.scratch, &state.out);
                                            in_block[*it] = Indices(state.out);
                                          }
                                        });
          std::vector<Neighbour> ring;
          for (std::size_t q = 0; q < queries.size(); ++q) {
            SCOPED_TRACE(testing::Message() << "kind " << kind << " cell " << cell << " k " << k
                                            << " max_radius " << max_radius << " query " << q);
            const std::vector<std::uint32_t> expected = BruteForce(points, queries[q], k, max_radius);
            ASSERT_EQ(in_block[q], expected);
            grid.Nearest(queries[q], k, max_radius, &ring);
            ASSERT_EQ(Indices(ring), expected);
            ASSERT_TRUE(std::is_sorted(ring.begin(), ring.end())) << "Nearest() returns nearest first";
          }
        }
      }
    }
  }
}

TEST(NeighbourGrid, EveryFiniteQueryIsVisitedOnce) {
  std::mt19937_64 rng(3);
  const Points points = MakeCloud(0, rng);
  const NeighbourGrid grid(points, 0.005f);
  Points queries = points;
  queries.push_back(Eigen::Vector3f(5.0f, 5.0f, 5.0f));
  std::vector<int> visits(queries.size(), 0);
  struct State {};
  grid.ForEachQueryBlock<State>(
      queries, nullptr,
      [&](const NeighbourGrid::Block&, const std::uint32_t* begin, const std::uint32_t* end, State&) {
        for (const std::uint32_t* it = begin; it != end; ++it) ++visits[*it];
      });
  for (std::size_t i = 0; i < queries.size(); ++i) EXPECT_EQ(visits[i], queries[i].allFinite() ? 1 : 0) << i;
}

TEST(NeighbourGrid, SuggestedCellSizeTracksDensity) {
  // A 1 mm lattice on a plane: the 9th neighbour (itself included) is at most ~1.5 mm away.
  Points lattice;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j)
      lattice.emplace_back(0.001f * static_cast<float>(i), 0.001f * static_cast<float>(j), 0.0f);
  }
  const float cell = NeighbourGrid::SuggestCellSizeForNearest(lattice, 9);
  EXPECT_GT(cell, 0.0009f);
  EXPECT_LT(cell, 0.0016f);
  EXPECT_EQ(NeighbourGrid::SuggestCellSizeForNearest({}, 9), 0.0f);
}

}  // namespace
}  // namespace tubepick::internal
