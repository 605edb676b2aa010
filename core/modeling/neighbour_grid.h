#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "core/common/stop_token.h"
#include "core/common/thread_budget.h"
#include "core/common/types.h"

namespace tubepick::internal {

/// A (squared distance, point index) pair. "The k nearest" are the k smallest such pairs, so
/// ties in distance are broken by index and every query has one answer.
using Neighbour = std::pair<float, std::uint32_t>;

/// A uniform hash grid over a point set for fixed-radius and k-nearest-neighbour queries.
/// Cheaper than a kd-tree for the dense, surface-like clouds of a scanner: a query scans the few
/// cells around the query point, whose points are contiguous in memory. Non-finite points are
/// left out. Immutable after construction, so concurrent queries are safe.
class NeighbourGrid {
 public:
  /// @pre cell_size > 0. The cell size is only a performance knob (ideally about the query
  /// radius, or the expected distance to the k-th neighbour); results never depend on it.
  NeighbourGrid(const Points& points, float cell_size);

  float cell_size() const { return cell_size_; }
  /// Number of (finite) points in the grid.
  std::size_t size() const { return sorted_index_.size(); }

  /// The k nearest points to q within max_radius (distance <= max_radius; infinity for no
  /// limit), nearest first, ties by index. A point at q itself is included. Replaces *out.
  /// Scans rings of cells around q; a query far from the points (an outlier, a sparse cloud)
  /// visits the occupied cells instead, so a query costs O(cells + points) at worst.
  void Nearest(const Eigen::Vector3f& q, std::size_t k, float max_radius, std::vector<Neighbour>* out) const;

  /// Visits the points in cell order (original indices): querying in this order keeps the
  /// touched cells in cache.
  const std::vector<std::uint32_t>& cell_order() const { return sorted_index_; }

  /// The points of the 3×3×3 cells around one cell, contiguous (structure of arrays). Every grid
  /// point closer than Bound(q) to a query q of the centre cell is in the block (up to rounding,
  /// which NearestInBlock() allows for).
  struct Block {
    std::vector<float> x, y, z;
    std::vector<std::uint32_t> index;
    /// Occupied cell c holds the points [cell_begin[c], cell_begin[c + 1]); its box is
    /// [cell_lo[c], cell_lo[c] + cell size].
    std::vector<std::uint32_t> cell_begin;
    std::vector<Eigen::Vector3f> cell_lo;
    /// The block's box.
    Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();

    std::size_t size() const { return index.size(); }
    /// Distance from q (inside the box) to the box's boundary; 0 outside.
    float Bound(const Eigen::Vector3f& q) const {
      const float b = std::min((q - lo).minCoeff(), (hi - q).minCoeff());
      return b > 0.0f ? b : 0.0f;
    }
  };

  /// Calls visit(block, begin, end, state) for groups of queries sharing a grid cell, with that
  /// cell's block, so that the block is gathered once per group. [begin, end) holds indices into
  /// `queries`. Groups run in parallel on ResolveThreads(threads) OpenMP threads; `state` is a
  /// default-constructed State per thread. Stops early (leaving queries unvisited) once `stop` says so: the
  /// caller then calls ThrowIfStopped.
  template <typename State, typename Visit>
  void ForEachQueryBlock(const Points& queries, std::uint32_t threads, const StopToken* stop,
                         Visit&& visit) const;

  /// Memory reused between NearestInBlock() calls of one thread, and a squared search radius
  /// guessed from the previous (nearby) query.
  struct NearestScratch {
    std::vector<float> d2;
    std::vector<Neighbour> candidates, spill;
    float guess2 = 0.0f;
  };

  /// The same set as Nearest(), found in `block` (q's block) when it provably holds it, by the
  /// ring search otherwise. The order is deterministic but not by distance.
  void NearestInBlock(const Block& block, const Eigen::Vector3f& q, std::size_t k, float max_radius,
                      NearestScratch* scratch, std::vector<Neighbour>* out) const;

  /// Median, over a deterministic subsample of the grid's points, of the distance to their k-th
  /// nearest point (the point itself counted), capped at max_radius. 0 for an empty grid.
  float MedianNearestDistance(std::size_t k, float max_radius) const;

  /// A cell size that makes k-nearest queries on `points` cheap (about the median distance to the
  /// k-th neighbour, estimated on a provisional grid). Positive whenever `points` is non-empty.
  static float SuggestCellSizeForNearest(const Points& points, std::size_t k);

 private:
  struct Cell {
    std::uint64_t key;
    std::uint32_t begin;
    std::uint32_t end;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  using GroupVisit =
      std::function<void(int thread, const Block&, const std::uint32_t*, const std::uint32_t*)>;
  /// The OpenMP loop behind ForEachQueryBlock() on `threads` ≥ 1 threads; `thread` is in
  /// [0, threads).
  void ForEachGroup(const Points& queries, int threads, const StopToken* stop, const GroupVisit& visit) const;

  struct QueryGroups {
    /// Query indices, grouped.
    std::vector<std::uint32_t> order;
    /// Group g is order[begin[g], begin[g + 1]).
    std::vector<std::uint32_t> begin;
  };
  /// Groups queries by their (occupied) grid cell; queries elsewhere get a group each.
  QueryGroups GroupQueries(const Points& queries) const;
  /// Fills `block` for the cell containing q (which may be outside the grid).
  void GatherBlock(const Eigen::Vector3f& q, Block* block) const;

  Eigen::Vector3i CellOf(const Eigen::Vector3f& p) const;
  /// The cell containing p without clamping to the grid (bounded to avoid overflow).
  Eigen::Vector3i UnclampedCellOf(const Eigen::Vector3f& p) const;
  static std::uint64_t Key(int x, int y, int z) {
    return (static_cast<std::uint64_t>(x) << 42) | (static_cast<std::uint64_t>(y) << 21) |
           static_cast<std::uint64_t>(z);
  }
  /// The cell's [begin, end) range in sorted_points_, or nullptr for an empty cell.
  const Cell* Find(int x, int y, int z) const;
  /// Nearest()'s search once rings get too costly: merges the points within max_r2 of the
  /// occupied cells outside the rings already scanned (Chebyshev distance < ring from c) into
  /// *out, keeping the k smallest, and skipping cells too far to hold any of them.
  void NearestInRemainingCells(const Eigen::Vector3f& q, const Eigen::Vector3i& c, int ring, std::size_t k,
                               float max_r2, float slack, std::vector<Neighbour>* out) const;
  /// Home slot of a key: Fibonacci hashing, the top bits of key × 2^64/φ, to which every bit
  /// of the key contributes (the low bits of the product ignore the high bits of the key, i.e.
  /// x, so cells along x would share a slot and probe long clusters).
  std::uint64_t HashSlot(std::uint64_t key) const { return (key * 0x9E3779B97F4A7C15ULL) >> shift_; }
  /// How far, at most, rounding can put a grid point on the wrong side of a cell face computed
  /// near q (cell assignment, cell corners): a few float ulps of the coordinates involved.
  float Slack(const Eigen::Vector3f& q) const { return slack_ + 1e-6f * q.cwiseAbs().maxCoeff(); }
  /// A bound, safe against rounding, on the distance from q to the points outside a box whose
  /// faces are at least `bound` from q as computed: if it is positive, every such point has a
  /// squared distance (as computed) greater than its square, and than max_radius² if it is at
  /// least max_radius. `slack` is Slack(q).
  static float SafeBound(float bound, float slack) { return std::max(bound * (1.0f - 1e-6f) - slack, 0.0f); }

  float cell_size_;
  float inv_cell_size_;
  /// The points' bounding box is [origin_, hi_].
  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  Eigen::Vector3f hi_ = Eigen::Vector3f::Zero();
  /// Slack() for a query near the grid.
  float slack_ = 0.0f;
  /// Number of cells along each axis (cell coordinates are in [0, dims)).
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<Eigen::Vector3f> sorted_points_;
  std::vector<std::uint32_t> sorted_index_;
  std::vector<Cell> table_;
  /// The occupied cells in the order of their points.
  std::vector<Cell> cells_;
  /// A non-empty grid's table_ has mask_ + 1 = 2^(64 - shift_) slots.
  std::uint64_t mask_ = 0;
  int shift_ = 63;
};

template <typename State, typename Visit>
void NeighbourGrid::ForEachQueryBlock(const Points& queries, std::uint32_t threads, const StopToken* stop,
                                      Visit&& visit) const {
  // One State per thread, each on its own cache lines.
  struct alignas(64) PaddedState {
    State state{};
  };
  const int width = ResolveThreads(threads);
  std::vector<PaddedState> states(static_cast<std::size_t>(width));
  ForEachGroup(queries, width, stop,
               [&](int thread, const Block& block, const std::uint32_t* begin, const std::uint32_t* end) {
                 visit(block, begin, end, states[static_cast<std::size_t>(thread)].state);
               });
}

}  // namespace tubepick::internal
