#include "core/modeling/cylinder_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <random>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/cylinder_model.h"

namespace tubepick {
namespace {

using internal::CylinderDistance;
using internal::CylinderModel;
using internal::SoaCloud;

// Minimal samples whose normals are closer than ~5.7° to parallel give an ill-conditioned axis.
constexpr double kMinSampleSinAngle = 0.1;

std::string Str(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

void Validate(const CylinderFitParams& p) {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw InvalidArgument(message);
  };
  require(p.min_inliers >= 1, "cylinders.min_inliers: must be >= 1, got 0");
  require(p.min_radius > 0.0 && std::isfinite(p.min_radius),
          "cylinders.min_radius: must be a positive number of metres, got " + Str(p.min_radius));
  require(p.max_radius > 0.0 && std::isfinite(p.max_radius),
          "cylinders.max_radius: must be a positive number of metres, got " + Str(p.max_radius));
  require(p.min_radius <= p.max_radius, "cylinders.min_radius: " + Str(p.min_radius) +
                                            " exceeds cylinders.max_radius " + Str(p.max_radius));
  require(p.distance_threshold > 0.0 && std::isfinite(p.distance_threshold),
          "cylinders.distance_threshold: must be positive, got " + Str(p.distance_threshold));
  require(p.normal_distance_weight >= 0.0 && p.normal_distance_weight <= 1.0,
          "cylinders.normal_distance_weight: must be in [0, 1], got " + Str(p.normal_distance_weight));
  require(p.max_iterations >= 1, "cylinders.max_iterations: must be >= 1, got 0");
  require(p.probability > 0.0 && p.probability < 1.0,
          "cylinders.probability: must be in (0, 1), got " + Str(p.probability));
  require(p.safety_length >= 0.0 && std::isfinite(p.safety_length),
          "cylinders.safety_length: must be >= 0 metres, got " + Str(p.safety_length));
  require(p.safety_radius >= 0.0 && std::isfinite(p.safety_radius),
          "cylinders.safety_radius: must be >= 0 metres, got " + Str(p.safety_radius));
}

// Uniform integer in [0, n), n > 0 (Lemire's multiply-shift; the same on every standard library).
std::uint64_t UniformBelow(std::mt19937_64& rng, std::uint64_t n) {
  return static_cast<std::uint64_t>((static_cast<unsigned __int128>(rng()) * n) >> 64);
}

// Points of the working set (cloud indices `index`) as offsets from `origin`.
SoaCloud MakeSoa(const OrientedPoints& cloud, const std::vector<std::uint32_t>& index,
                 const Eigen::Vector3d& origin) {
  SoaCloud soa;
  soa.origin = origin;
  const Eigen::Index n = static_cast<Eigen::Index>(index.size());
  for (Eigen::ArrayXf* a : {&soa.x, &soa.y, &soa.z, &soa.nx, &soa.ny, &soa.nz}) a->resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d p = cloud.points[index[i]].cast<double>() - origin;
    const Eigen::Vector3f& nrm = cloud.normals[index[i]];
    soa.x[i] = static_cast<float>(p.x());
    soa.y[i] = static_cast<float>(p.y());
    soa.z[i] = static_cast<float>(p.z());
    soa.nx[i] = nrm.x();
    soa.ny[i] = nrm.y();
    soa.nz[i] = nrm.z();
  }
  return soa;
}

bool RadiusInRange(const CylinderModel& m, const CylinderFitParams& p) {
  return m.radius >= p.min_radius && m.radius <= p.max_radius;
}

// One RANSAC run (PCL's adaptive stopping rule): the model with the most inliers, or nullopt.
std::optional<CylinderModel> Ransac(const SoaCloud& soa, const CylinderFitParams& params,
                                    std::mt19937_64& rng, CylinderDistance& distance, const StopToken* stop) {
  const std::uint64_t n = static_cast<std::uint64_t>(soa.size());
  if (n < 2) return std::nullopt;
  const float threshold = static_cast<float>(params.distance_threshold);
  const double log_probability = std::log(1.0 - params.probability);
  const std::uint64_t max_skip = 10ull * params.max_iterations;
  std::optional<CylinderModel> best;
  Eigen::Index best_count = 0;
  // Iterations needed for `probability`, set from the first model with an inlier and updated with
  // each better one. Unbounded (max_iterations) until then: starting at 1, as PCL does, ends the
  // search after one model whenever the first valid sample has no inlier at all (likely with a
  // strict normal term), which abandoned whole segments.
  double needed = std::numeric_limits<double>::infinity();
  std::uint64_t iterations = 0, skipped = 0;
  while (static_cast<double>(iterations) < needed && iterations < params.max_iterations) {
    const std::uint64_t i1 = UniformBelow(rng, n);
    std::uint64_t i2 = UniformBelow(rng, n - 1);
    if (i2 >= i1) ++i2;
    const auto model = internal::CylinderFromTwoPoints(soa.point(i1), soa.normal(i1), soa.point(i2),
                                                       soa.normal(i2), kMinSampleSinAngle);
    if (!model || !RadiusInRange(*model, params)) {
      if (++skipped >= max_skip) break;
      continue;
    }
    ++iterations;
    if (iterations % 64 == 0) ThrowIfStopped(stop, "cylinder fitting");
    const Eigen::Index count = (distance.Compute(soa, *model) < threshold).count();
    if (count > best_count) {
      best_count = count;
      best = model;
      const double w = static_cast<double>(count) / static_cast<double>(n);
      const double p_no_outliers = std::clamp(1.0 - w * w, std::numeric_limits<double>::epsilon(),
                                              1.0 - std::numeric_limits<double>::epsilon());
      needed = log_probability / std::log(p_no_outliers);
    }
  }
  return best;
}

// A deterministic orientation for an axis (its sign is otherwise arbitrary).
Eigen::Vector3d Canonical(const Eigen::Vector3d& a) {
  for (int i = 0; i < 3; ++i) {
    if (std::abs(a[i]) > 1e-9) return a[i] > 0.0 ? a : Eigen::Vector3d(-a);
  }
  return a;
}

// Keeps only the largest run of inliers that is contiguous along the axis (no gap longer than
// `max_gap` between consecutive inliers' axial positions); the other inliers become outliers
// again. A cylinder then models one continuous piece of tube: without this, a model fitted after
// an earlier cylinder's points were removed could take inliers on both sides of that hole and
// span over it, overlapping the earlier cylinder (thesis §4.6.2), which the joining cannot undo.
void KeepLargestContiguousRun(const SoaCloud& soa, const CylinderModel& model, double max_gap,
                              Eigen::Array<bool, Eigen::Dynamic, 1>& is_inlier) {
  const Eigen::Vector3d a = model.direction.normalized();
  std::vector<std::pair<double, Eigen::Index>> along;
  along.reserve(static_cast<std::size_t>(is_inlier.count()));
  for (Eigen::Index i = 0; i < soa.size(); ++i) {
    if (is_inlier[i]) along.emplace_back((soa.point(i) - model.point).dot(a), i);
  }
  if (along.size() < 2) return;
  std::sort(along.begin(), along.end());
  std::size_t best_begin = 0, best_end = 0, begin = 0;
  for (std::size_t k = 1; k <= along.size(); ++k) {
    if (k == along.size() || along[k].first - along[k - 1].first > max_gap) {
      if (k - begin > best_end - best_begin) best_begin = begin, best_end = k;
      begin = k;
    }
  }
  if (best_end - best_begin == along.size()) return;
  is_inlier.setConstant(false);
  for (std::size_t k = best_begin; k < best_end; ++k) is_inlier[along[k].second] = true;
}

}  // namespace

std::vector<FittedCylinder> FitCylinders(const OrientedPoints& cloud, const Segment& segment,
                                         std::uint32_t segment_id, const CylinderFitParams& params,
                                         std::uint64_t seed, const StopToken* stop) {
  Validate(params);
  if (cloud.normals.size() != cloud.points.size()) {
    throw InvalidArgument("cylinders: the cloud has " + std::to_string(cloud.points.size()) + " points but " +
                          std::to_string(cloud.normals.size()) + " normals");
  }
  // The working set: the segment's points with finite position and normal.
  std::vector<std::uint32_t> remaining;
  remaining.reserve(segment.size());
  for (const std::uint32_t i : segment) {
    if (i >= cloud.size()) {
      throw InvalidArgument("cylinders: segment " + std::to_string(segment_id) + " has point index " +
                            std::to_string(i) + " but the cloud has " + std::to_string(cloud.size()) +
                            " points");
    }
    if (cloud.points[i].allFinite() && cloud.normals[i].allFinite()) remaining.push_back(i);
  }
  std::vector<FittedCylinder> result;
  if (remaining.size() < params.min_inliers) return result;

  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const std::uint32_t i : remaining) origin += cloud.points[i].cast<double>();
  origin /= static_cast<double>(remaining.size());

  std::mt19937_64 rng(seed);
  CylinderDistance distance(params.normal_distance_weight);
  const float threshold = static_cast<float>(params.distance_threshold);
  std::vector<Eigen::Vector3d> inlier_points;
  while (remaining.size() >= params.min_inliers) {
    ThrowIfStopped(stop, "cylinder fitting");
    const SoaCloud soa = MakeSoa(cloud, remaining, origin);
    std::optional<CylinderModel> model = Ransac(soa, params, rng, distance, stop);
    if (!model) break;
    // Gaps along the axis longer than this split the inliers; only the largest run is kept.
    const double max_gap = std::max(2.0 * params.safety_length, model->radius);
    Eigen::Array<bool, Eigen::Dynamic, 1> is_inlier = distance.Compute(soa, *model) < threshold;
    KeepLargestContiguousRun(soa, *model, max_gap, is_inlier);
    if (static_cast<std::uint64_t>(is_inlier.count()) < params.min_inliers) break;

    if (params.refine) {
      inlier_points.clear();
      for (Eigen::Index i = 0; i < soa.size(); ++i) {
        if (is_inlier[i]) inlier_points.push_back(soa.point(i));
      }
      const auto refined = internal::RefineCylinder(inlier_points, *model);
      if (refined && RadiusInRange(*refined, params)) {
        Eigen::Array<bool, Eigen::Dynamic, 1> refined_inlier = distance.Compute(soa, *refined) < threshold;
        KeepLargestContiguousRun(soa, *refined, max_gap, refined_inlier);
        if (static_cast<std::uint64_t>(refined_inlier.count()) >= params.min_inliers) {
          model = refined;
          is_inlier = std::move(refined_inlier);
        }
      }
    }

    // Endpoints from the inliers' extent along the axis.
    const Eigen::Vector3d a = Canonical(model->direction);
    const Eigen::Vector3d c = model->point;
    double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
    FittedCylinder fitted;
    for (Eigen::Index i = 0; i < soa.size(); ++i) {
      if (!is_inlier[i]) continue;
      const double t = (soa.point(i) - c).dot(a);
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
      fitted.inliers.push_back(remaining[static_cast<std::size_t>(i)]);
    }
    if (t_max - t_min < model->radius) {
      // Shorter than its radius (a sliver, e.g. the inside of an open tube end seen from above):
      // its axis direction is unreliable and would mislead the joining's angle test. Its inliers
      // are dropped without a cylinder and the fitting goes on with the other points.
      std::vector<std::uint32_t> kept;
      kept.reserve(remaining.size());
      for (Eigen::Index i = 0; i < soa.size(); ++i) {
        if (!is_inlier[i]) kept.push_back(remaining[static_cast<std::size_t>(i)]);
      }
      remaining = std::move(kept);
      continue;
    }
    fitted.cylinder.start = origin + c + t_min * a;
    fitted.cylinder.end = origin + c + t_max * a;
    fitted.cylinder.radius = model->radius;
    fitted.cylinder.segment_id = segment_id;
    fitted.cylinder.inlier_count = static_cast<std::uint32_t>(fitted.inliers.size());
    result.push_back(std::move(fitted));

    // Remove the inliers and the other points inside the safety zone: the cylinder extended by
    // safety_length at both bases, with radius safety_radius.
    const double t_lo = t_min - params.safety_length, t_hi = t_max + params.safety_length;
    const double r2 = params.safety_radius * params.safety_radius;
    std::vector<std::uint32_t> kept;
    kept.reserve(remaining.size());
    for (Eigen::Index i = 0; i < soa.size(); ++i) {
      if (is_inlier[i]) continue;
      const Eigen::Vector3d d = soa.point(i) - c;
      const double t = d.dot(a);
      if (t >= t_lo && t <= t_hi && (d - t * a).squaredNorm() <= r2) continue;
      kept.push_back(remaining[static_cast<std::size_t>(i)]);
    }
    remaining = std::move(kept);
  }
  return result;
}

}  // namespace tubepick
