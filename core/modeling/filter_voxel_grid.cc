// voxel_grid: one original point per occupied voxel, the one nearest to the voxel's centroid.

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/common/errors.h"
#include "core/modeling/filters_internal.h"

namespace tubepick::internal {
namespace {

constexpr std::uint64_t kEmptyKey = std::numeric_limits<std::uint64_t>::max();

/// A voxel's integer coordinates relative to the cloud's lowest voxel: `x` along bin x and
/// `row` numbering the (y, z) rows of voxels.
struct VoxelKey {
  std::uint64_t x = 0;
  std::uint64_t row = 0;
  bool operator==(const VoxelKey&) const = default;
};

/// Open-addressing (linear probing) map from voxel to a dense voxel id, grown by doubling so
/// its size follows the number of occupied voxels, not of points.
class VoxelIdMap {
 public:
  VoxelIdMap(std::uint64_t dim_x, std::size_t expected_voxels) : dim_x_(dim_x) {
    Rehash(std::bit_ceil(std::max<std::size_t>(64, 2 * expected_voxels)));
  }

  /// The id of the voxel, assigning the next id when it is new.
  std::uint32_t FindOrInsert(const VoxelKey& voxel) {
    const std::uint64_t key = voxel.x + dim_x_ * voxel.row;
    for (std::size_t slot = Home(voxel);; slot = (slot + 1) & mask_) {
      Slot& s = slots_[slot];
      if (s.key == key) return s.id;
      if (s.key == kEmptyKey) {
        s = Slot{key, size_};
        ++size_;
        if (2 * size_ > slots_.size()) Rehash(2 * slots_.size());
        return size_ - 1;
      }
    }
  }

 private:
  struct Slot {
    std::uint64_t key = kEmptyKey;
    std::uint32_t id = 0;
  };

  /// x + hash(row): a row of voxels takes consecutive slots, so a scanner's row-by-row order
  /// walks the table nearly sequentially (measured faster than scattering every voxel).
  std::size_t Home(const VoxelKey& voxel) const {
    return static_cast<std::size_t>(voxel.x + ((voxel.row * 0x9E3779B97F4A7C15ull) >> 20)) & mask_;
  }

  void Rehash(std::size_t capacity) {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(capacity, Slot{});
    mask_ = capacity - 1;
    for (const Slot& s : old) {
      if (s.key == kEmptyKey) continue;
      std::size_t slot = Home(VoxelKey{s.key % dim_x_, s.key / dim_x_});
      while (slots_[slot].key != kEmptyKey) slot = (slot + 1) & mask_;
      slots_[slot] = s;
    }
  }

  std::uint64_t dim_x_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  std::uint32_t size_ = 0;
};

/// floor() by truncation: std::floor is a libm call without SSE4.1, and this is the hot loop.
std::int64_t FloorToInt(double v) {
  const auto i = static_cast<std::int64_t>(v);
  return i - (v < static_cast<double>(i) ? 1 : 0);
}

}  // namespace

std::vector<std::uint32_t> VoxelGridFilter(const VoxelGridParams& params, const Points& points_Bin,
                                           const StopToken* stop) {
  const double inv_leaf = 1.0 / params.leaf_size;
  const std::size_t n = points_Bin.size();

  // Voxel index bounds over the finite points (voxels are aligned at multiples of leaf_size).
  // Plain scalars: this loop and the next are the hot ones on 2 M-point clouds.
  float lo_xf = std::numeric_limits<float>::infinity(), lo_yf = lo_xf, lo_zf = lo_xf;
  float hi_xf = -lo_xf, hi_yf = hi_xf, hi_zf = hi_xf;
  for (const Eigen::Vector3f& p : points_Bin) {
    if (!p.allFinite()) continue;
    lo_xf = std::min(lo_xf, p.x());
    lo_yf = std::min(lo_yf, p.y());
    lo_zf = std::min(lo_zf, p.z());
    hi_xf = std::max(hi_xf, p.x());
    hi_yf = std::max(hi_yf, p.y());
    hi_zf = std::max(hi_zf, p.z());
  }
  const Eigen::Array3f lo(lo_xf, lo_yf, lo_zf), hi(hi_xf, hi_yf, hi_zf);
  if (!(lo <= hi).all()) return {};  // no finite point
  const Eigen::Array3d lo_scaled = lo.cast<double>() * inv_leaf;
  const Eigen::Array3d hi_scaled = hi.cast<double>() * inv_leaf;
  const Eigen::Array3d extent = hi_scaled.floor() - lo_scaled.floor() + 1.0;
  if (!(extent.prod() < 0x1p62) || !(lo_scaled.abs().maxCoeff() < 0x1p52) ||
      !(hi_scaled.abs().maxCoeff() < 0x1p52)) {
    std::ostringstream os;
    os << "voxel_grid.leaf_size: too small for the cloud's extent (" << extent.x() << " x " << extent.y()
       << " x " << extent.z() << " voxels), got " << params.leaf_size;
    throw InvalidArgument(os.str());
  }
  const std::int64_t lo_x = FloorToInt(lo_scaled.x());
  const std::int64_t lo_y = FloorToInt(lo_scaled.y());
  const std::int64_t lo_z = FloorToInt(lo_scaled.z());
  const auto dim_x = static_cast<std::uint64_t>(extent.x());
  const auto dim_y = static_cast<std::uint64_t>(extent.y());
  auto voxel_of_point = [&](const Eigen::Vector3f& p) {
    const auto iy = static_cast<std::uint64_t>(FloorToInt(p.y() * inv_leaf) - lo_y);
    const auto iz = static_cast<std::uint64_t>(FloorToInt(p.z() * inv_leaf) - lo_z);
    return VoxelKey{static_cast<std::uint64_t>(FloorToInt(p.x() * inv_leaf) - lo_x), iy + dim_y * iz};
  };

  // Pass 1: voxel of every point and per-voxel coordinate sums. Scans are ordered, so
  // consecutive points often share a voxel: such a run is summed locally and looked up once.
  constexpr std::uint32_t kNoVoxel = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> voxel_of(n, kNoVoxel);
  std::vector<Eigen::Vector4d> sums;  // x, y, z, count
  sums.reserve(n / 8 + 16);
  VoxelIdMap ids(dim_x, n / 8 + 16);
  VoxelKey run_voxel{kEmptyKey, kEmptyKey};
  std::uint32_t run_id = 0;
  double run_x = 0.0, run_y = 0.0, run_z = 0.0, run_count = 0.0;  // locals, not captured: kept in registers
  for (std::size_t i = 0; i < n; ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "filter voxel_grid");
    const Eigen::Vector3f& p = points_Bin[i];
    if (!p.allFinite()) continue;
    const VoxelKey voxel = voxel_of_point(p);
    if (!(voxel == run_voxel)) {
      if (run_count > 0.0) sums[run_id] += Eigen::Vector4d(run_x, run_y, run_z, run_count);
      run_x = run_y = run_z = run_count = 0.0;
      run_voxel = voxel;
      run_id = ids.FindOrInsert(voxel);
      if (run_id == sums.size()) sums.emplace_back(Eigen::Vector4d::Zero());
    }
    voxel_of[i] = run_id;
    run_x += p.x();
    run_y += p.y();
    run_z += p.z();
    run_count += 1.0;
  }
  if (run_count > 0.0) sums[run_id] += Eigen::Vector4d(run_x, run_y, run_z, run_count);

  // Pass 2: per voxel, the point nearest to the centroid (ties: the lowest index).
  std::vector<Eigen::Vector3d> centroid(sums.size());
  for (std::size_t v = 0; v < sums.size(); ++v) centroid[v] = sums[v].head<3>() / sums[v].w();
  std::vector<double> best_distance(sums.size(), std::numeric_limits<double>::infinity());
  std::vector<std::uint32_t> best_point(sums.size(), 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "filter voxel_grid");
    const std::uint32_t v = voxel_of[i];
    if (v == kNoVoxel) continue;
    const double d2 = (points_Bin[i].cast<double>() - centroid[v]).squaredNorm();
    if (d2 < best_distance[v]) {
      best_distance[v] = d2;
      best_point[v] = static_cast<std::uint32_t>(i);
    }
  }

  // Increasing order without sorting: mark, then sweep.
  std::vector<std::uint8_t> keep(n, 0);
  for (std::uint32_t i : best_point) keep[i] = 1;
  std::vector<std::uint32_t> kept;
  kept.reserve(best_point.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

}  // namespace tubepick::internal
