#include "core/modeling/neighbour_grid.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <limits>

namespace tubepick::internal {
namespace {

// Cell coordinates are packed into 21 bits per axis.
constexpr int kMaxCellsPerAxis = (1 << 21) - 1;

bool IsFinite(const Eigen::Vector3f& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

// Reorders v[0, m) so that its first k (0 < k < m) are the k smallest by (distance, index),
// in an unspecified order, and returns the k-th smallest distance. All distances are <= top;
// `spill` has room for m. A bucket pass on the squared distance (nearly uniform for points on a
// surface) leaves only the boundary bucket to nth_element: much cheaper than nth_element over
// all m on these short lists.
float SelectSmallest(Neighbour* v, std::size_t m, std::size_t k, float top, Neighbour* spill) {
  constexpr int kBuckets = 64;
  if (!(top > 0.0f) || !std::isfinite(top)) {
    top = 0.0f;
    for (std::size_t i = 0; i < m; ++i) top = std::max(top, v[i].first);
  }
  if (!(top > 0.0f)) {
    std::nth_element(v, v + k - 1, v + m);
    return v[k - 1].first;
  }
  const float scale = (kBuckets - 1) / top;
  std::uint32_t count[kBuckets] = {};
  for (std::size_t i = 0; i < m; ++i) ++count[std::min(static_cast<int>(v[i].first * scale), kBuckets - 1)];
  int boundary = 0;
  std::size_t below = 0;  // elements in the buckets before `boundary`
  while (below + count[boundary] < k) below += count[boundary++];
  std::size_t front = 0, spilled = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const int b = std::min(static_cast<int>(v[i].first * scale), kBuckets - 1);
    if (b < boundary) {
      v[front++] = v[i];
    } else if (b == boundary) {
      spill[spilled++] = v[i];
    }
  }
  const std::size_t need = k - below;
  if (need < spilled) std::nth_element(spill, spill + need - 1, spill + spilled);
  const float kth = std::max_element(spill, spill + need)->first;
  std::copy(spill, spill + need, v + front);
  return kth;
}

}  // namespace

NeighbourGrid::NeighbourGrid(const Points& points, float cell_size) : cell_size_(cell_size) {
  assert(cell_size > 0.0f);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  std::size_t finite = 0;
  for (const Eigen::Vector3f& p : points) {
    if (!IsFinite(p)) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    ++finite;
  }
  inv_cell_size_ = 1.0f / cell_size_;
  if (finite == 0) return;
  // Widen the cells if the cloud spans more cells than the key can hold (far outliers).
  const float extent = (hi - lo).maxCoeff();
  if (extent * inv_cell_size_ >= static_cast<float>(kMaxCellsPerAxis - 2)) {
    cell_size_ = extent / static_cast<float>(kMaxCellsPerAxis - 4);
    inv_cell_size_ = 1.0f / cell_size_;
  }
  origin_ = lo;
  hi_ = hi;
  // A few float ulps (2^-24 relative) of the largest coordinate, for the rounding of cell
  // assignments and of cell corners: ~10⁻⁶ m for a cloud within a metre of the origin.
  slack_ = 3e-6f * lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).maxCoeff();
  for (int a = 0; a < 3; ++a) {
    dims_[a] = std::min(kMaxCellsPerAxis, static_cast<int>((hi[a] - lo[a]) * inv_cell_size_) + 1);
  }

  // Pass 1: cell of every point, cells numbered in order of first appearance; count per cell.
  std::uint64_t capacity = 64;
  table_.assign(capacity, Cell{kEmpty, 0, 0});
  mask_ = capacity - 1;
  shift_ = 64 - 6;
  std::vector<std::uint32_t> cell_of(points.size(), 0);
  std::vector<std::uint32_t> count;
  std::vector<std::uint64_t> key_of_cell;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!IsFinite(points[i])) continue;
    const Eigen::Vector3i c = CellOf(points[i]);
    const std::uint64_t key = Key(c.x(), c.y(), c.z());
    std::uint64_t slot = HashSlot(key);
    while (table_[slot].key != kEmpty && table_[slot].key != key) slot = (slot + 1) & mask_;
    if (table_[slot].key == kEmpty) {
      table_[slot] = Cell{key, static_cast<std::uint32_t>(count.size()), 0};
      count.push_back(0);
      key_of_cell.push_back(key);
      if (2 * count.size() > capacity) {  // Grow: keep the load factor at most 1/2.
        capacity *= 4;
        mask_ = capacity - 1;
        shift_ -= 2;
        std::vector<Cell> old = std::move(table_);
        table_.assign(capacity, Cell{kEmpty, 0, 0});
        for (const Cell& cell : old) {
          if (cell.key == kEmpty) continue;
          std::uint64_t s = HashSlot(cell.key);
          while (table_[s].key != kEmpty) s = (s + 1) & mask_;
          table_[s] = cell;
        }
        slot = HashSlot(key);
        while (table_[slot].key != key) slot = (slot + 1) & mask_;
      }
    }
    cell_of[i] = table_[slot].begin;  // still the cell number during pass 1
    ++count[table_[slot].begin];
  }

  // Pass 2: cell ranges by prefix sums, then scatter the points.
  std::vector<std::uint32_t> begin(count.size() + 1, 0);
  for (std::size_t c = 0; c < count.size(); ++c) begin[c + 1] = begin[c] + count[c];
  cells_.resize(count.size());
  for (std::size_t c = 0; c < count.size(); ++c) cells_[c] = Cell{key_of_cell[c], begin[c], begin[c + 1]};
  for (Cell& cell : table_) {
    if (cell.key == kEmpty) continue;
    const std::uint32_t c = cell.begin;
    cell.begin = begin[c];
    cell.end = begin[c + 1];
  }
  sorted_points_.resize(finite);
  sorted_index_.resize(finite);
  std::vector<std::uint32_t> next(begin.begin(), begin.end() - 1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!IsFinite(points[i])) continue;
    const std::uint32_t at = next[cell_of[i]]++;
    sorted_points_[at] = points[i];
    sorted_index_[at] = static_cast<std::uint32_t>(i);
  }
}

Eigen::Vector3i NeighbourGrid::CellOf(const Eigen::Vector3f& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const int v = static_cast<int>((p[a] - origin_[a]) * inv_cell_size_);
    c[a] = std::clamp(v, 0, dims_[a] - 1);
  }
  return c;
}

Eigen::Vector3i NeighbourGrid::UnclampedCellOf(const Eigen::Vector3f& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const float v = std::floor((p[a] - origin_[a]) * inv_cell_size_);
    c[a] = static_cast<int>(std::clamp(v, -4.0f * kMaxCellsPerAxis, 4.0f * kMaxCellsPerAxis));
  }
  return c;
}

void NeighbourGrid::ForEachGroup(const Points& queries, int threads, const StopToken* stop,
                                 const GroupVisit& visit) const {
  const QueryGroups groups = GroupQueries(queries);
  const std::int64_t n_groups = static_cast<std::int64_t>(groups.begin.size()) - 1;
  std::atomic<bool> stopped{false};
#pragma omp parallel num_threads(threads)
  {
    Block block;
    const int thread = omp_get_thread_num();
#pragma omp for schedule(dynamic, 4)
    for (std::int64_t g = 0; g < n_groups; ++g) {
      if (stop != nullptr && (stopped.load(std::memory_order_relaxed) || stop->should_stop())) {
        stopped.store(true, std::memory_order_relaxed);
        continue;
      }
      const std::uint32_t* begin = groups.order.data() + groups.begin[static_cast<std::size_t>(g)];
      const std::uint32_t* end = groups.order.data() + groups.begin[static_cast<std::size_t>(g) + 1];
      GatherBlock(queries[*begin], &block);
      visit(thread, block, begin, end);
    }
  }
}

NeighbourGrid::QueryGroups NeighbourGrid::GroupQueries(const Points& queries) const {
  // Queries in an occupied cell are keyed by the cell's offset in sorted_points_ (so groups come
  // in the cells' order); the others form groups of one, after them.
  constexpr std::uint32_t kAlone = std::numeric_limits<std::uint32_t>::max();
  const std::size_t n_keys = sorted_points_.size();
  std::vector<std::uint32_t> key(queries.size(), kAlone);
  std::vector<std::uint32_t> count(n_keys + 1, 0);
  std::size_t alone = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    if (!IsFinite(queries[i])) continue;
    const Eigen::Vector3i c = UnclampedCellOf(queries[i]);
    const Cell* cell =
        (c.array() >= 0).all() && (c.array() < dims_.array()).all() ? Find(c.x(), c.y(), c.z()) : nullptr;
    if (cell == nullptr) {
      ++alone;
      continue;
    }
    key[i] = cell->begin;
    ++count[cell->begin];
  }
  QueryGroups groups;
  std::vector<std::uint32_t> start(n_keys + 1, 0);
  groups.begin.push_back(0);
  for (std::size_t k = 0; k < n_keys; ++k) {
    start[k + 1] = start[k] + count[k];
    if (count[k] > 0) groups.begin.push_back(start[k + 1]);
  }
  const std::uint32_t grouped = start[n_keys];
  for (std::size_t a = 1; a <= alone; ++a) groups.begin.push_back(grouped + static_cast<std::uint32_t>(a));
  groups.order.resize(grouped + alone);
  std::uint32_t next_alone = grouped;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    if (key[i] != kAlone) {
      groups.order[start[key[i]]++] = static_cast<std::uint32_t>(i);
    } else if (IsFinite(queries[i])) {
      groups.order[next_alone++] = static_cast<std::uint32_t>(i);
    }
  }
  return groups;
}

void NeighbourGrid::GatherBlock(const Eigen::Vector3f& q, Block* block) const {
  block->x.clear();
  block->y.clear();
  block->z.clear();
  block->index.clear();
  block->cell_begin.assign(1, 0);
  block->cell_lo.clear();
  const Eigen::Vector3i c = UnclampedCellOf(q);
  block->lo = origin_ + (c.array() - 1).cast<float>().matrix() * cell_size_;
  block->hi = origin_ + (c.array() + 2).cast<float>().matrix() * cell_size_;
  const int x0 = std::max(c.x() - 1, 0), x1 = std::min(c.x() + 1, dims_.x() - 1);
  const int y0 = std::max(c.y() - 1, 0), y1 = std::min(c.y() + 1, dims_.y() - 1);
  const int z0 = std::max(c.z() - 1, 0), z1 = std::min(c.z() + 1, dims_.z() - 1);
  for (int x = x0; x <= x1; ++x) {
    for (int y = y0; y <= y1; ++y) {
      for (int z = z0; z <= z1; ++z) {
        const Cell* cell = Find(x, y, z);
        if (cell == nullptr) continue;
        for (std::uint32_t i = cell->begin; i < cell->end; ++i) {
          block->x.push_back(sorted_points_[i].x());
          block->y.push_back(sorted_points_[i].y());
          block->z.push_back(sorted_points_[i].z());
          block->index.push_back(sorted_index_[i]);
        }
        block->cell_begin.push_back(static_cast<std::uint32_t>(block->index.size()));
        block->cell_lo.push_back(origin_ + Eigen::Vector3f(x, y, z) * cell_size_);
      }
    }
  }
}

void NeighbourGrid::NearestInBlock(const Block& block, const Eigen::Vector3f& q, std::size_t k,
                                   float max_radius, NearestScratch* scratch,
                                   std::vector<Neighbour>* out) const {
  out->clear();
  if (k == 0) return;
  const std::size_t n = block.size();
  // Grown, never shrunk: resizing a vector of pairs would zero-fill it on every call.
  if (scratch->d2.size() < n) {
    scratch->d2.resize(n);
    scratch->candidates.resize(n);
    scratch->spill.resize(n);
  }
  float* d2 = scratch->d2.data();
  Neighbour* o = scratch->candidates.data();
  const float qx = q.x(), qy = q.y(), qz = q.z();
  const float* bx = block.x.data();
  const float* by = block.y.data();
  const float* bz = block.z.data();
  const float limit2 = max_radius * max_radius;
  const float slack = Slack(q);
  const float bound = SafeBound(block.Bound(q), slack);
  const float bound2 = bound * bound;

  // Squared distances of the points [begin, end) (vectorised), then those within threshold2
  // appended to the candidates, branch-free.
  auto scan = [&](std::size_t begin, std::size_t end, float threshold2, std::size_t m) {
    for (std::size_t i = begin; i < end; ++i) {
      const float dx = bx[i] - qx, dy = by[i] - qy, dz = bz[i] - qz;
      d2[i] = dx * dx + dy * dy + dz * dz;
    }
    for (std::size_t i = begin; i < end; ++i) {
      o[m] = Neighbour(d2[i], block.index[i]);
      m += d2[i] <= threshold2 ? 1 : 0;
    }
    return m;
  };
  // The k smallest of the m candidates (all within threshold2), into *out; returns the k-th
  // squared distance.
  auto select = [&](std::size_t m, float threshold2) {
    const std::size_t kk = std::min(k, m);
    float kth = 0.0f;
    if (kk < m) {
      kth = SelectSmallest(o, m, kk, threshold2, scratch->spill.data());
    } else {
      for (std::size_t i = 0; i < kk; ++i) kth = std::max(kth, o[i].first);
    }
    out->assign(o, o + kk);
    return kth;
  };

  // Try the radius guessed from the previous query, then the largest radius the block answers
  // for (the distance to its boundary, or max_radius if smaller). Only cells within the radius
  // are scanned. Exact when k points are found nearer than anything outside the block, or when
  // the block holds all of max_radius. Bounds and cell distances allow for rounding (Slack()).
  const float safe2 = std::min(bound2, limit2);
  auto attempt = [&](float threshold2) {
    const float size = cell_size_;
    std::size_t m = 0;
    for (std::size_t c = 0; c + 1 < block.cell_begin.size(); ++c) {
      const Eigen::Vector3f& lo = block.cell_lo[c];
      const float ex = std::max({lo.x() - qx - slack, qx - lo.x() - size - slack, 0.0f});
      const float ey = std::max({lo.y() - qy - slack, qy - lo.y() - size - slack, 0.0f});
      const float ez = std::max({lo.z() - qz - slack, qz - lo.z() - size - slack, 0.0f});
      if ((ex * ex + ey * ey + ez * ez) * (1.0f - 2e-6f) > threshold2) continue;
      m = scan(block.cell_begin[c], block.cell_begin[c + 1], threshold2, m);
    }
    const float kth = select(m, threshold2);
    if ((m >= k && kth < bound2) || (threshold2 >= limit2 && bound > 0.0f && limit2 <= bound2)) {
      if (out->size() == k) scratch->guess2 = 1.3f * kth;
      return true;
    }
    return false;
  };
  if (scratch->guess2 > 0.0f && scratch->guess2 < safe2 && attempt(scratch->guess2)) return;
  if (attempt(safe2)) return;
  // The ring search.
  Nearest(q, k, max_radius, out);
  if (out->size() == k) scratch->guess2 = 1.3f * out->back().first;
}

const NeighbourGrid::Cell* NeighbourGrid::Find(int x, int y, int z) const {
  const std::uint64_t key = Key(x, y, z);
  std::uint64_t slot = HashSlot(key);
  while (true) {
    const Cell& cell = table_[slot];
    if (cell.key == key) return &cell;
    if (cell.key == kEmpty) return nullptr;
    slot = (slot + 1) & mask_;
  }
}

void NeighbourGrid::Nearest(const Eigen::Vector3f& q, std::size_t k, float max_radius,
                            std::vector<Neighbour>* out) const {
  out->clear();
  if (k == 0 || sorted_points_.empty() || !IsFinite(q)) return;
  const float max_r2 = max_radius * max_radius;  // infinity stays infinity
  const float slack = Slack(q);
  // Nothing within max_radius if q is farther than that from the points' bounding box.
  const Eigen::Vector3f gap = (origin_ - q).cwiseMax(q - hi_).cwiseMax(0.0f);
  const float gap_bound = SafeBound(gap.norm(), slack);
  if (gap_bound > 0.0f && gap_bound >= max_radius) return;

  auto scan = [&](std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t i = begin; i < end; ++i) {
      const float dx = sorted_points_[i].x() - q.x(), dy = sorted_points_[i].y() - q.y();
      const float dz = sorted_points_[i].z() - q.z();
      const float d2 = dx * dx + dy * dy + dz * dz;  // the same rounding as NearestInBlock()
      if (d2 <= max_r2) out->emplace_back(d2, sorted_index_[i]);
    }
  };

  const Eigen::Vector3i c = UnclampedCellOf(q);  // q may lie outside the grid's box
  // Rings closer than the grid's box hold no cells.
  int ring = 0;
  for (int a = 0; a < 3; ++a) ring = std::max({ring, -c[a], c[a] - (dims_[a] - 1)});
  // Lookups (mostly of empty cells once rings grow) are capped at about what a visit of every
  // occupied cell costs: a query in a large empty region (an outlier, a query far from the grid)
  // then visits the occupied cells instead, so it costs O(cells + points) at worst.
  const std::uint64_t lookup_budget = std::min(cells_.size() / 8, sorted_points_.size() / 4) + 64;
  std::uint64_t looked_up = 0;
  std::uint64_t box_cells = 0;  // cells of the previous ring's box, clipped to the grid
  for (;; ++ring) {
    // The shell of cells at Chebyshev distance `ring` from c, clipped to the grid (never empty:
    // the first ring reaches the grid, whose box is disjoint from the rings inside it).
    const int x0 = std::max(c.x() - ring, 0), x1 = std::min(c.x() + ring, dims_.x() - 1);
    const int y0 = std::max(c.y() - ring, 0), y1 = std::min(c.y() + ring, dims_.y() - 1);
    const int z0 = std::max(c.z() - ring, 0), z1 = std::min(c.z() + ring, dims_.z() - 1);
    const std::uint64_t cells = static_cast<std::uint64_t>(x1 - x0 + 1) *
                                static_cast<std::uint64_t>(y1 - y0 + 1) *
                                static_cast<std::uint64_t>(z1 - z0 + 1);
    looked_up += cells - box_cells;  // the shell
    box_cells = cells;
    if (looked_up > lookup_budget) {
      NearestInRemainingCells(q, c, ring, k, max_r2, slack, out);
      break;
    }
    auto scan_cell = [&](int x, int y, int z) {
      if (const Cell* cell = Find(x, y, z)) scan(cell->begin, cell->end);
    };
    for (int x = x0; x <= x1; ++x) {
      const bool x_face = std::abs(x - c.x()) == ring;
      for (int y = y0; y <= y1; ++y) {
        if (x_face || std::abs(y - c.y()) == ring) {
          for (int z = z0; z <= z1; ++z) scan_cell(x, y, z);
        } else {
          if (c.z() - ring >= 0 && c.z() - ring < dims_.z()) scan_cell(x, y, c.z() - ring);
          if (ring > 0 && c.z() + ring >= 0 && c.z() + ring < dims_.z()) scan_cell(x, y, c.z() + ring);
        }
      }
    }
    // Every point not scanned yet is farther than `bound` from q.
    float bound = std::numeric_limits<float>::max();
    bool covers_grid = true;
    for (int a = 0; a < 3; ++a) {
      const float lo = origin_[a] + static_cast<float>(c[a] - ring) * cell_size_;
      const float hi = origin_[a] + static_cast<float>(c[a] + ring + 1) * cell_size_;
      bound = std::min({bound, q[a] - lo, hi - q[a]});
      covers_grid = covers_grid && c[a] - ring <= 0 && c[a] + ring >= dims_[a] - 1;
    }
    bound = SafeBound(bound, slack);
    if (covers_grid || (bound > 0.0f && bound >= max_radius)) break;
    if (out->size() >= k) {
      // Only the k smallest can be the answer: drop the others (so a ring costs O(k + its
      // points) here), and stop once the k-th is nearer than anything not scanned.
      std::nth_element(out->begin(), out->begin() + static_cast<std::ptrdiff_t>(k - 1), out->end());
      out->resize(k);
      if (out->back().first < bound * bound) break;
    }
  }
  if (out->size() > k) {
    std::nth_element(out->begin(), out->begin() + static_cast<std::ptrdiff_t>(k), out->end());
    out->resize(k);
  }
  std::sort(out->begin(), out->end());
}

void NeighbourGrid::NearestInRemainingCells(const Eigen::Vector3f& q, const Eigen::Vector3i& c, int ring,
                                            std::size_t k, float max_r2, float slack,
                                            std::vector<Neighbour>* out) const {
  // The k best so far, as a max-heap on (squared distance, index).
  if (out->size() > k) {
    std::nth_element(out->begin(), out->begin() + static_cast<std::ptrdiff_t>(k - 1), out->end());
    out->resize(k);
  }
  std::make_heap(out->begin(), out->end());
  constexpr std::uint64_t kAxis = kMaxCellsPerAxis;  // the 21 bits of one coordinate in a Key()
  for (const Cell& cell : cells_) {
    const Eigen::Vector3i xyz(static_cast<int>(cell.key >> 42), static_cast<int>((cell.key >> 21) & kAxis),
                              static_cast<int>(cell.key & kAxis));
    if ((xyz - c).cwiseAbs().maxCoeff() < ring) continue;  // scanned by the rings
    // Skip the cell if all its points are farther than the k-th so far, or than max_radius.
    const float limit2 = out->size() == k ? std::min(out->front().first, max_r2) : max_r2;
    float gap2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
      const float lo = origin_[a] + static_cast<float>(xyz[a]) * cell_size_;
      const float gap = std::max({lo - q[a] - slack, q[a] - lo - cell_size_ - slack, 0.0f});
      gap2 += gap * gap;
    }
    if (gap2 * (1.0f - 2e-6f) > limit2) continue;
    for (std::uint32_t i = cell.begin; i < cell.end; ++i) {
      const float dx = sorted_points_[i].x() - q.x(), dy = sorted_points_[i].y() - q.y();
      const float dz = sorted_points_[i].z() - q.z();
      const Neighbour candidate(dx * dx + dy * dy + dz * dz, sorted_index_[i]);
      if (candidate.first > max_r2) continue;
      if (out->size() < k) {
        out->push_back(candidate);
        std::push_heap(out->begin(), out->end());
      } else if (candidate < out->front()) {
        std::pop_heap(out->begin(), out->end());
        out->back() = candidate;
        std::push_heap(out->begin(), out->end());
      }
    }
  }
}

float NeighbourGrid::MedianNearestDistance(std::size_t k, float max_radius) const {
  if (sorted_points_.empty() || k == 0) return 0.0f;
  constexpr std::size_t kSamples = 255;
  const std::size_t stride = std::max<std::size_t>(1, sorted_points_.size() / kSamples);
  std::vector<float> kth;
  std::vector<Neighbour> neighbours;
  for (std::size_t i = stride / 2; i < sorted_points_.size(); i += stride) {
    Nearest(sorted_points_[i], k, max_radius, &neighbours);
    kth.push_back(neighbours.size() < k ? max_radius : std::sqrt(neighbours.back().first));
  }
  const auto mid = kth.begin() + static_cast<std::ptrdiff_t>(kth.size() / 2);
  std::nth_element(kth.begin(), mid, kth.end());
  return *mid;
}

float NeighbourGrid::SuggestCellSizeForNearest(const Points& points, std::size_t k) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  std::size_t n = 0;
  for (const Eigen::Vector3f& p : points) {
    if (!IsFinite(p)) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    ++n;
  }
  if (n == 0) return 0.0f;
  // Provisional size: the k-th neighbour distance if the points filled the box's largest face
  // (surface-like data) or its volume, whichever is larger.
  const Eigen::Vector3d e = (hi - lo).cast<double>();
  const double kk = static_cast<double>(std::max<std::size_t>(k, 1));
  const double area = std::max({e.x() * e.y(), e.y() * e.z(), e.x() * e.z()});
  double s0 = std::max(std::sqrt(kk * area / (M_PI * static_cast<double>(n))),
                       std::cbrt(kk * e.prod() / (4.19 * static_cast<double>(n))));
  if (!(s0 > 0.0)) s0 = e.maxCoeff() * kk / static_cast<double>(n);
  if (!(s0 > 1e-6)) s0 = 1e-3;
  const NeighbourGrid provisional(points, static_cast<float>(s0));
  const float median = provisional.MedianNearestDistance(k, std::numeric_limits<float>::infinity());
  return median > 1e-6f ? median : static_cast<float>(s0);
}

}  // namespace tubepick::internal
