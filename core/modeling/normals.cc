#include "core/modeling/normals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>

#include "core/common/errors.h"
#include "core/modeling/neighbour_grid.h"

namespace tubepick {
namespace {

using internal::Neighbour;
using internal::NeighbourGrid;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Moments of a neighbourhood, relative to the query point (small numbers, so no cancellation).
struct Moments {
  int n = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  // xx, xy, xz, yy, yz, zz
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
};

// Moments of a neighbour list in fixed point (units of radius / 2^20): integer sums do not
// depend on the order of the neighbours, which differs with the search path taken, so the
// normal of a point is bit-identical whatever the thread count or the other queries.
class FixedPointMoments {
 public:
  explicit FixedPointMoments(float radius) : scale_(static_cast<double>(1 << 20) / radius) {}

  void Add(const Eigen::Vector3f& d) {
    // Truncation: cheap (no libm call), deterministic, and off by less than a unit (~nm).
    const auto x = static_cast<std::int64_t>(d.x() * scale_), y = static_cast<std::int64_t>(d.y() * scale_);
    const auto z = static_cast<std::int64_t>(d.z() * scale_);
    ++n_;
    s_[0] += x;
    s_[1] += y;
    s_[2] += z;
    s_[3] += x * x;
    s_[4] += x * y;
    s_[5] += x * z;
    s_[6] += y * y;
    s_[7] += y * z;
    s_[8] += z * z;
  }

  Moments ToMoments() const {
    Moments m;
    const double inv = 1.0 / scale_, inv2 = inv * inv;
    m.n = n_;
    m.sum =
        Eigen::Vector3d(static_cast<double>(s_[0]), static_cast<double>(s_[1]), static_cast<double>(s_[2])) *
        inv;
    m.xx = static_cast<double>(s_[3]) * inv2;
    m.xy = static_cast<double>(s_[4]) * inv2;
    m.xz = static_cast<double>(s_[5]) * inv2;
    m.yy = static_cast<double>(s_[6]) * inv2;
    m.yz = static_cast<double>(s_[7]) * inv2;
    m.zz = static_cast<double>(s_[8]) * inv2;
    return m;
  }

 private:
  double scale_;
  int n_ = 0;
  std::int64_t s_[9] = {};
};

// Moments of the block's points within sqrt(r2) of q: one branch-free pass over eight lanes at
// a time (Eigen packets), in float: the values are offsets of at most about the radius.
void AccumulateWithin(const NeighbourGrid::Block& block, const Eigen::Vector3f& q, float r2, Moments* m) {
  using Lanes = Eigen::Array<float, 8, 1>;
  const std::size_t n = block.size();
  const float* bx = block.x.data();
  const float* by = block.y.data();
  const float* bz = block.z.data();
  Lanes c = Lanes::Zero(), sx = c, sy = c, sz = c, sxx = c, sxy = c, sxz = c, syy = c, syz = c, szz = c;
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const Lanes dx = Lanes::Map(bx + i) - q.x();
    const Lanes dy = Lanes::Map(by + i) - q.y();
    const Lanes dz = Lanes::Map(bz + i) - q.z();
    const Lanes w = (dx.square() + dy.square() + dz.square() <= r2).select(Lanes::Ones(), Lanes::Zero());
    const Lanes wx = w * dx, wy = w * dy, wz = w * dz;
    c += w;
    sx += wx;
    sy += wy;
    sz += wz;
    sxx += wx * dx;
    sxy += wx * dy;
    sxz += wx * dz;
    syy += wy * dy;
    syz += wy * dz;
    szz += wz * dz;
  }
  float tail[10] = {};
  for (; i < n; ++i) {
    const float dx = bx[i] - q.x(), dy = by[i] - q.y(), dz = bz[i] - q.z();
    if (dx * dx + dy * dy + dz * dz > r2) continue;
    const float v[10] = {1.0f, dx, dy, dz, dx * dx, dx * dy, dx * dz, dy * dy, dy * dz, dz * dz};
    for (int j = 0; j < 10; ++j) tail[j] += v[j];
  }
  m->n = static_cast<int>(c.sum() + tail[0]);
  m->sum = Eigen::Vector3d(sx.sum() + tail[1], sy.sum() + tail[2], sz.sum() + tail[3]);
  m->xx = sxx.sum() + tail[4];
  m->xy = sxy.sum() + tail[5];
  m->xz = sxz.sum() + tail[6];
  m->yy = syy.sum() + tail[7];
  m->yz = syz.sum() + tail[8];
  m->zz = szz.sum() + tail[9];
}

// PCA of the neighbourhood: the eigenvector of the smallest covariance eigenvalue, flipped to
// face the viewpoint, and the surface variation λ0/(λ0+λ1+λ2) (pcl::computePointNormal).
void NormalFromMoments(const Moments& m, const Eigen::Vector3f& q, const Eigen::Vector3f& viewpoint,
                       Eigen::Vector3f* normal, float* curvature) {
  if (m.n < 3) {
    normal->setConstant(kNaN);
    *curvature = kNaN;
    return;
  }
  const double inv_n = 1.0 / m.n;
  const Eigen::Vector3d mean = m.sum * inv_n;
  Eigen::Matrix3d cov;
  cov(0, 0) = m.xx * inv_n - mean.x() * mean.x();
  cov(0, 1) = m.xy * inv_n - mean.x() * mean.y();
  cov(0, 2) = m.xz * inv_n - mean.x() * mean.z();
  cov(1, 1) = m.yy * inv_n - mean.y() * mean.y();
  cov(1, 2) = m.yz * inv_n - mean.y() * mean.z();
  cov(2, 2) = m.zz * inv_n - mean.z() * mean.z();
  cov(1, 0) = cov(0, 1);
  cov(2, 0) = cov(0, 2);
  cov(2, 1) = cov(1, 2);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov);
  const Eigen::Vector3d lambda = solver.eigenvalues().cwiseMax(0.0);  // ascending
  Eigen::Vector3f n = solver.eigenvectors().col(0).cast<float>();
  if (!n.allFinite() || n.squaredNorm() < 0.5f) {
    normal->setConstant(kNaN);
    *curvature = kNaN;
    return;
  }
  n.normalize();
  if (n.dot(viewpoint - q) < 0.0f) n = -n;
  *normal = n;
  const double total = lambda.sum();
  *curvature = total > 0.0 ? static_cast<float>(lambda[0] / total) : 0.0f;
}

}  // namespace

OrientedPoints EstimateNormals(const Points& query_Bin, const Points& surface_Bin, const NormalParams& params,
                               const Eigen::Vector3f& viewpoint_Bin, const StopToken* stop,
                               std::uint32_t threads) {
  if (!(params.radius > 0.0) || !std::isfinite(params.radius)) {
    throw InvalidArgument("normals.radius: must be a positive number of metres, got " +
                          std::to_string(params.radius));
  }
  OrientedPoints out;
  out.points = query_Bin;
  out.normals.assign(query_Bin.size(), Eigen::Vector3f::Constant(kNaN));
  out.curvature.assign(query_Bin.size(), kNaN);
  if (query_Bin.empty()) return out;

  const float radius = static_cast<float>(params.radius);
  const std::size_t k = params.max_neighbours;
  // Cells of the radius: a query's block then holds all its neighbours. With a neighbour cap
  // much smaller than what the radius holds, cells of about the distance to the k-th neighbour,
  // so that a query scans few points beyond its k nearest.
  NeighbourGrid grid(surface_Bin, radius);
  if (k > 0) {
    const float kth = grid.MedianNearestDistance(k, radius);
    const float cell = std::clamp(1.6f * kth, 0.25f * radius, radius);
    if (cell < 0.8f * radius) grid = NeighbourGrid(surface_Bin, cell);
  }

  struct State {
    NeighbourGrid::NearestScratch scratch;
    std::vector<Neighbour> neighbours;
  };
  const float r2 = radius * radius;
  auto estimate = [&](const NeighbourGrid::Block& block, const std::uint32_t* begin, const std::uint32_t* end,
                      State& state) {
    for (const std::uint32_t* it = begin; it != end; ++it) {
      const Eigen::Vector3f& q = query_Bin[*it];
      Moments moments;
      if (k == 0) {
        AccumulateWithin(block, q, r2, &moments);
      } else {
        grid.NearestInBlock(block, q, k, radius, &state.scratch, &state.neighbours);
        FixedPointMoments fixed(radius);
        for (const Neighbour& nb : state.neighbours) fixed.Add(surface_Bin[nb.second] - q);
        moments = fixed.ToMoments();
      }
      NormalFromMoments(moments, q, viewpoint_Bin, &out.normals[*it], &out.curvature[*it]);
    }
  };
  grid.ForEachQueryBlock<State>(query_Bin, threads, stop, estimate);
  ThrowIfStopped(stop, "normals");
  return out;
}

}  // namespace tubepick
