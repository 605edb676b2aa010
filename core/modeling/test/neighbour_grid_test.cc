#include "core/modeling/neighbour_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <random>
#include <set>
#include <thread>
#include <vector>

#include <omp.h>

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
  if (all.size() > k) {
    std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k), all.end());
    all.resize(k);
  }
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

// Both search paths (NearestInBlock() over the query blocks, and Nearest()) against brute force.
void ExpectMatchesBruteForce(const Points& points, const NeighbourGrid& grid, const Points& queries,
                             std::size_t k, float max_radius) {
  std::vector<std::vector<std::uint32_t>> in_block(queries.size());
  struct State {
    NeighbourGrid::NearestScratch scratch;
    std::vector<Neighbour> out;
  };
  grid.ForEachQueryBlock<State>(queries, 2, nullptr,
                                [&](const NeighbourGrid::Block& block, const std::uint32_t* begin,
                                    const std::uint32_t* end, State& state) {
                                  for (const std::uint32_t* it = begin; it != end; ++it) {
                                    grid.NearestInBlock(block, queries[*it], k, max_radius, &state.scratch,
                                                        &state.out);
                                    in_block[*it] = Indices(state.out);
                                  }
                                });
  std::vector<Neighbour> ring;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    SCOPED_TRACE(testing::Message() << "k " << k << " max_radius " << max_radius << " query " << q);
    const std::vector<std::uint32_t> expected = BruteForce(points, queries[q], k, max_radius);
    ASSERT_EQ(in_block[q], expected);
    grid.Nearest(queries[q], k, max_radius, &ring);
    ASSERT_EQ(Indices(ring), expected);
    ASSERT_TRUE(std::is_sorted(ring.begin(), ring.end())) << "Nearest() returns nearest first";
  }
}

TEST(NeighbourGrid, NearestMatchesBruteForce) {
  std::mt19937_64 rng(7);
  for (int kind = 0; kind < 4; ++kind) {
    const Points points = MakeCloud(kind, rng);
    for (const float cell : {0.001f, 0.01f}) {
      const NeighbourGrid grid(points, cell);
      EXPECT_EQ(grid.size(), points.size() - 1);  // the NaN point is left out
      Points queries(points.begin(), points.end() - 1);
      queries.push_back(Eigen::Vector3f(0.3f, 2.0f, -0.1f));  // outside the grid
      for (const std::size_t k : {1u, 7u, 30u}) {
        for (const float max_radius : {0.006f, kInf}) {
          SCOPED_TRACE(testing::Message() << "kind " << kind << " cell " << cell);
          ASSERT_NO_FATAL_FAILURE(ExpectMatchesBruteForce(points, grid, queries, k, max_radius));
        }
      }
    }
  }
}

// Points in cells of a millimetre, about 0.2 m apart, and queries far from all of them: the
// searches must not walk the empty cells in between (~10⁹ in the grid's box alone).
TEST(NeighbourGrid, FarQueryOnSparseCloud) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  Points points(100);
  for (Eigen::Vector3f& p : points) p = Eigen::Vector3f(u(rng), u(rng), u(rng));
  const NeighbourGrid grid(points, 0.001f);
  Points queries = points;
  queries.emplace_back(0.0f, 0.0f, 0.0f);        // inside the grid's box, among empty cells
  queries.emplace_back(0.3f, 2.0f, -0.1f);       // outside it
  queries.emplace_back(1e6f, -1e6f, 1e6f);       // far beyond the cell coordinates' range
  for (const std::size_t k : {1u, 30u, 200u}) {  // 200: more than there are points
    for (const float max_radius : {0.2f, kInf}) {
      ASSERT_NO_FATAL_FAILURE(ExpectMatchesBruteForce(points, grid, queries, k, max_radius));
    }
  }
}

// Points on cell faces (multiples of the cell size, or an ulp off) and a radius of one cell:
// many distances equal the radius, or the distance to a ring's or a block's boundary, up to
// rounding. The searches' bounds must allow for that rounding.
TEST(NeighbourGrid, ExactOnCellFaces) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> lattice(0, 7), nudge(-1, 1);
  constexpr float kCell = 0.003f;
  for (int trial = 0; trial < 8; ++trial) {
    Points points(200);
    for (Eigen::Vector3f& p : points) {
      for (int a = 0; a < 3; ++a) {
        p[a] = static_cast<float>(lattice(rng)) * kCell;
        if (const int n = nudge(rng); n != 0) p[a] = std::nextafter(p[a], static_cast<float>(n));
      }
    }
    const NeighbourGrid grid(points, kCell);
    for (const std::size_t k : {5u, 20u}) {
      for (const float max_radius : {kCell, kInf}) {
        SCOPED_TRACE(testing::Message() << "trial " << trial);
        ASSERT_NO_FATAL_FAILURE(ExpectMatchesBruteForce(points, grid, points, k, max_radius));
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
      queries, 0, nullptr,
      [&](const NeighbourGrid::Block&, const std::uint32_t* begin, const std::uint32_t* end, State&) {
        for (const std::uint32_t* it = begin; it != end; ++it) ++visits[*it];
      });
  for (std::size_t i = 0; i < queries.size(); ++i) EXPECT_EQ(visits[i], queries[i].allFinite() ? 1 : 0) << i;
}

// The width of the parallel loop is the caller's `threads`, whatever OpenMP's default (what
// OMP_NUM_THREADS sets) says: a 16-core default must not turn a 2-thread call into 16 threads.
TEST(NeighbourGrid, ParallelWidthIsTheCallersNotOpenMpDefault) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Points points(20000);
  for (Eigen::Vector3f& p : points) p = Eigen::Vector3f(u(rng), u(rng), u(rng));
  const NeighbourGrid grid(points, 0.05f);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(16);
  for (const std::uint32_t threads : {1u, 2u}) {
    std::mutex mu;
    std::set<std::thread::id> seen;
    struct State {
      int unused = 0;
    };
    std::vector<State*> states;
    grid.ForEachQueryBlock<State>(
        points, threads, nullptr,
        [&](const NeighbourGrid::Block&, const std::uint32_t*, const std::uint32_t*, State& state) {
          std::lock_guard lock(mu);
          seen.insert(std::this_thread::get_id());
          if (std::find(states.begin(), states.end(), &state) == states.end()) states.push_back(&state);
        });
    EXPECT_LE(seen.size(), threads) << threads;
    EXPECT_LE(states.size(), threads) << threads;
    if (threads == 1) {
      EXPECT_TRUE(seen.count(std::this_thread::get_id()));
    }
  }
  omp_set_num_threads(saved);
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
