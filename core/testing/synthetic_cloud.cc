#include "core/testing/synthetic_cloud.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/common/ray_intersect.h"

namespace tubepick::testing {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Primitive {
  Eigen::Vector3d a, b;  // b == a for a sphere
  double radius;
  int label;
  bool sphere;
};

}  // namespace

double SyntheticTube::length() const {
  double sum = 0.0;
  for (std::size_t i = 1; i < centreline.size(); ++i) sum += (centreline[i] - centreline[i - 1]).norm();
  return sum;
}

SyntheticTube StraightTube(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  return SyntheticTube{{a, b}, radius};
}

SyntheticTube FloorTube(const std::vector<Eigen::Vector2d>& xy, double radius, double lift) {
  SyntheticTube tube;
  tube.radius = radius;
  for (const auto& p : xy) tube.centreline.emplace_back(p.x(), p.y(), radius + lift);
  return tube;
}

SyntheticCloud RenderSyntheticCloud(const std::vector<SyntheticTube>& tubes,
                                    const SyntheticCloudParams& params) {
  const Eigen::Isometry3d X_SensorBin = params.X_BinSensor.inverse();
  const int width = static_cast<int>(std::ceil(2.0 * params.half_fov_x / params.pixel_angle));
  const int height = static_cast<int>(std::ceil(2.0 * params.half_fov_y / params.pixel_angle));
  std::vector<double> depth(static_cast<std::size_t>(width) * height, kInf);  // ray parameter t
  std::vector<int> label(depth.size(), -2);

  auto pixel_direction = [&](int i, int j) {
    const double u = -params.half_fov_x + (i + 0.5) * params.pixel_angle;
    const double v = -params.half_fov_y + (j + 0.5) * params.pixel_angle;
    return Eigen::Vector3d(u, v, 1.0).normalized();
  };

  // Primitives in the sensor frame: a cylinder per centreline segment, a sphere per vertex.
  std::vector<Primitive> primitives;
  for (std::size_t k = 0; k < tubes.size(); ++k) {
    const auto& line = tubes[k].centreline;
    for (std::size_t i = 0; i < line.size(); ++i) {
      const Eigen::Vector3d p = X_SensorBin * line[i];
      primitives.push_back({p, p, tubes[k].radius, static_cast<int>(k), true});
      if (i + 1 < line.size()) {
        primitives.push_back({p, X_SensorBin * line[i + 1], tubes[k].radius, static_cast<int>(k), false});
      }
    }
  }

  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const Primitive& prim : primitives) {
    // Screen-space bounds of the primitive's axis-aligned box (it is in front of the sensor).
    const Eigen::Vector3d lo = prim.a.cwiseMin(prim.b).array() - prim.radius;
    const Eigen::Vector3d hi = prim.a.cwiseMax(prim.b).array() + prim.radius;
    if (lo.z() <= 1e-6) continue;
    double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d q((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                              (c & 4) ? hi.z() : lo.z());
      umin = std::min(umin, q.x() / q.z());
      umax = std::max(umax, q.x() / q.z());
      vmin = std::min(vmin, q.y() / q.z());
      vmax = std::max(vmax, q.y() / q.z());
    }
    const int i0 = std::max(0, static_cast<int>(std::floor((umin + params.half_fov_x) / params.pixel_angle)));
    const int i1 =
        std::min(width - 1, static_cast<int>(std::ceil((umax + params.half_fov_x) / params.pixel_angle)));
    const int j0 = std::max(0, static_cast<int>(std::floor((vmin + params.half_fov_y) / params.pixel_angle)));
    const int j1 =
        std::min(height - 1, static_cast<int>(std::ceil((vmax + params.half_fov_y) / params.pixel_angle)));
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const Eigen::Vector3d d = pixel_direction(i, j);
        const double t = prim.sphere ? RaySphere(origin, d, prim.a, prim.radius)
                                     : RayCylinderSide(origin, d, prim.a, prim.b, prim.radius);
        const std::size_t idx = static_cast<std::size_t>(j) * width + i;
        if (t < depth[idx]) {
          depth[idx] = t;
          label[idx] = prim.label;
        }
      }
    }
  }

  if (params.floor) {
    // Floor plane z = 0 of the bin frame, in the sensor frame: n·p = c.
    const Eigen::Vector3d n = X_SensorBin.linear() * Eigen::Vector3d::UnitZ();
    const double c = n.dot(X_SensorBin.translation());
    for (int j = 0; j < height; ++j) {
      for (int i = 0; i < width; ++i) {
        const Eigen::Vector3d d = pixel_direction(i, j);
        const double t = RayPlane(origin, d, n, c);
        if (!std::isfinite(t)) continue;
        const Eigen::Vector3d p_Bin = params.X_BinSensor * (t * d);
        if (std::abs(p_Bin.x()) > 0.5 * params.floor_size.x() ||
            std::abs(p_Bin.y()) > 0.5 * params.floor_size.y()) {
          continue;
        }
        const std::size_t idx = static_cast<std::size_t>(j) * width + i;
        if (t < depth[idx]) {
          depth[idx] = t;
          label[idx] = -1;
        }
      }
    }
  }

  std::mt19937_64 rng(params.seed);
  std::normal_distribution<double> noise(0.0, params.depth_noise);
  SyntheticCloud cloud;
  for (int j = 0; j < height; ++j) {
    for (int i = 0; i < width; ++i) {
      const std::size_t idx = static_cast<std::size_t>(j) * width + i;
      if (!std::isfinite(depth[idx])) continue;
      const double t = depth[idx] + (params.depth_noise > 0.0 ? noise(rng) : 0.0);
      cloud.points_Sensor.push_back((t * pixel_direction(i, j)).cast<float>());
      cloud.label.push_back(label[idx]);
    }
  }
  return cloud;
}

}  // namespace tubepick::testing
