// plane_removal: RANSAC for the largest plane roughly perpendicular to an axis, with normals
// (the behaviour of pcl::SACSegmentationFromNormals with SACMODEL_NORMAL_PARALLEL_PLANE and
// pcl::RandomSampleConsensus), then removal of its inliers.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Eigenvalues>

#include "core/modeling/filters_internal.h"

namespace tubepick::internal {
namespace {

struct Plane {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // unit
  float offset = 0.0f;                                // normal·p + offset = 0
};

/// The points that can take part: finite, with a finite non-zero normal (normals made unit).
struct Candidates {
  std::vector<std::uint32_t> index;
  Points points;
  Points unit_normals;
};

Candidates SelectCandidates(const Points& points, const Points& normals) {
  Candidates c;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float norm = normals[i].norm();
    if (!points[i].allFinite() || !std::isfinite(norm) || norm < 1e-6f) continue;
    c.index.push_back(static_cast<std::uint32_t>(i));
    c.points.push_back(points[i]);
    c.unit_normals.push_back(normals[i] / norm);
  }
  return c;
}

/// Weighted distance as PCL's SampleConsensusModelNormalPlane: w·(angle between the point's
/// normal and the plane's, folded into [0, π/2]) + (1 − w)·|point-plane distance|.
class InlierTest {
 public:
  InlierTest(const PlaneRemovalParams& params)
      : w_(static_cast<float>(params.normal_distance_weight)),
        threshold_(static_cast<float>(params.distance_threshold)) {}

  bool operator()(const Plane& plane, const Eigen::Vector3f& p, const Eigen::Vector3f& unit_normal) const {
    const float euclidean = std::abs(plane.normal.dot(p) + plane.offset);
    if ((1.0f - w_) * euclidean >= threshold_) return false;  // the angle term cannot help
    const float angle = std::acos(std::min(1.0f, std::abs(plane.normal.dot(unit_normal))));
    return w_ * angle + (1.0f - w_) * euclidean < threshold_;
  }

 private:
  float w_;
  float threshold_;
};

std::size_t CountInliers(const Candidates& c, const Plane& plane, const InlierTest& is_inlier) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < c.points.size(); ++i)
    count += is_inlier(plane, c.points[i], c.unit_normals[i]) ? 1 : 0;
  return count;
}

/// Positions (into the candidates) of the inliers.
std::vector<std::size_t> SelectInliers(const Candidates& c, const Plane& plane, const InlierTest& is_inlier) {
  std::vector<std::size_t> inliers;
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    if (is_inlier(plane, c.points[i], c.unit_normals[i])) inliers.push_back(i);
  }
  return inliers;
}

/// Least-squares plane through the given candidates (PCA), as PCL's optimizeModelCoefficients.
Plane FitPlane(const Candidates& c, const std::vector<std::size_t>& members) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i : members) centroid += c.points[i].cast<double>();
  centroid /= static_cast<double>(members.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i : members) {
    const Eigen::Vector3d d = c.points[i].cast<double>() - centroid;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);  // smallest eigenvalue
  return Plane{normal.cast<float>(), static_cast<float>(-normal.dot(centroid))};
}

}  // namespace

std::vector<std::uint32_t> PlaneRemovalFilter(const PlaneRemovalParams& params, const Points& points_Bin,
                                              const Points& normals_Bin, std::uint64_t seed,
                                              const StopToken* stop) {
  std::vector<std::uint32_t> all(points_Bin.size());
  std::iota(all.begin(), all.end(), 0u);
  const Candidates candidates = SelectCandidates(points_Bin, normals_Bin);
  const std::size_t n = candidates.points.size();
  if (n < 3) return all;

  const Eigen::Vector3f axis = params.axis.normalized().cast<float>();
  const float min_cos_to_axis = static_cast<float>(std::cos(params.eps_angle));
  auto is_valid = [&](const Plane& plane) { return std::abs(plane.normal.dot(axis)) >= min_cos_to_axis; };
  const InlierTest is_inlier(params);

  // RANSAC with PCL's adaptive stop: k = log(1 − probability) / log(1 − w³), w the best inlier ratio.
  std::mt19937_64 rng(seed);
  const double log_probability = std::log(1.0 - params.probability);
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  double k = 1.0;
  std::int64_t best_count = -1;
  Plane best;
  std::size_t iterations = 0, skipped = 0;
  const std::size_t max_skipped = 10 * static_cast<std::size_t>(params.max_iterations);
  while (iterations < k && iterations < params.max_iterations && skipped < max_skipped) {
    ThrowIfStopped(stop, "filter plane_removal");
    const std::size_t a = UniformIndex(rng, n);
    const std::size_t b = UniformIndex(rng, n);
    const std::size_t c = UniformIndex(rng, n);
    const Eigen::Vector3d p0 = candidates.points[a].cast<double>();
    const Eigen::Vector3d e1 = candidates.points[b].cast<double>() - p0;
    const Eigen::Vector3d e2 = candidates.points[c].cast<double>() - p0;
    const Eigen::Vector3d cross = e1.cross(e2);
    const double cross_norm = cross.norm();
    if (a == b || b == c || a == c || !(cross_norm > 1e-9 * e1.norm() * e2.norm())) {  // degenerate sample
      ++skipped;
      continue;
    }
    const Eigen::Vector3d normal = cross / cross_norm;
    const Plane plane{normal.cast<float>(), static_cast<float>(-normal.dot(p0))};
    // A model off the axis counts as having no inliers (as PCL's isModelValid) but uses an iteration.
    const auto count =
        static_cast<std::int64_t>(is_valid(plane) ? CountInliers(candidates, plane, is_inlier) : 0);
    if (count > best_count) {
      best_count = count;
      best = plane;
      const double w = static_cast<double>(count) / static_cast<double>(n);
      const double p_no_outliers = std::clamp(1.0 - w * w * w, kEps, 1.0 - kEps);
      k = log_probability / std::log(p_no_outliers);
    }
    ++iterations;
  }
  if (best_count <= 0) return all;

  // Refit on the inliers and reselect, as SACSegmentation does with optimize_coefficients.
  std::vector<std::size_t> inliers = SelectInliers(candidates, best, is_inlier);
  if (inliers.size() >= 3) {
    const Plane refined = FitPlane(candidates, inliers);
    if (refined.normal.allFinite() && is_valid(refined)) {
      std::vector<std::size_t> refined_inliers = SelectInliers(candidates, refined, is_inlier);
      if (refined_inliers.size() >= 3) inliers = std::move(refined_inliers);
    }
  }
  if (inliers.size() < params.min_inliers) return all;

  std::vector<std::uint8_t> removed(points_Bin.size(), 0);
  for (std::size_t i : inliers) removed[candidates.index[i]] = 1;
  std::vector<std::uint32_t> kept;
  kept.reserve(points_Bin.size() - inliers.size());
  for (std::uint32_t i : all) {
    if (!removed[i]) kept.push_back(i);
  }
  return kept;
}

}  // namespace tubepick::internal
