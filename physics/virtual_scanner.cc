#include "physics/virtual_scanner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "core/common/errors.h"
#include "core/common/ray_intersect.h"
#include "core/common/thread_budget.h"
#include "physics/seeds.h"

namespace tubepick::physics {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNearZ = 1e-6;

enum class Kind { kSphere, kCylinder, kBox };

/// A primitive ready for casting: spheres and cylinders in the sensor frame (rays start at the
/// origin), boxes in the bin frame (they are axis-aligned there); plus its screen rectangle.
struct Primitive {
  Kind kind;
  Eigen::Vector3d a;  // sphere centre, cylinder start, box min corner
  Eigen::Vector3d b;  // cylinder end, box max corner
  double radius;
  std::int32_t label;
  int i0, i1, j0, j1;  // inclusive pixel bounds
};

/// Slab test of the ray o + t·d against the box [lo, hi]: nearest t > 0 and the axis of the face
/// hit; +inf when it misses.
double RayAlignedBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo,
                     const Eigen::Vector3d& hi, int* face_axis) {
  double t_near = -kInf, t_far = kInf;
  int near_axis = 0, far_axis = 0;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (o[k] < lo[k] || o[k] > hi[k]) return kInf;
      continue;
    }
    double t1 = (lo[k] - o[k]) / d[k], t2 = (hi[k] - o[k]) / d[k];
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_near) {
      t_near = t1;
      near_axis = k;
    }
    if (t2 < t_far) {
      t_far = t2;
      far_axis = k;
    }
    if (t_near > t_far || t_far <= 0.0) return kInf;
  }
  if (t_near > 0.0) {
    *face_axis = near_axis;
    return t_near;
  }
  *face_axis = far_axis;
  return t_far;
}

/// Pixel rectangle covering the projection of the box [lo, hi] (sensor frame); the whole image
/// when part of it is behind the sensor.
void ScreenBounds(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const PinholeIntrinsics& k,
                  Primitive& p) {
  p.i0 = 0;
  p.i1 = k.width - 1;
  p.j0 = 0;
  p.j1 = k.height - 1;
  if (lo.z() <= kNearZ) return;
  double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d q((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    const double u = k.fx * q.x() / q.z() + k.cx, v = k.fy * q.y() / q.z() + k.cy;
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  }
  // Clamp in double first: a primitive far off-screen must not overflow the int conversion.
  auto clamp_floor = [](double x, int hi_index) {
    return static_cast<int>(std::clamp(std::floor(x), -1.0, static_cast<double>(hi_index + 1)));
  };
  auto clamp_ceil = [](double x, int hi_index) {
    return static_cast<int>(std::clamp(std::ceil(x), -1.0, static_cast<double>(hi_index + 1)));
  };
  p.i0 = std::max(0, clamp_floor(umin, k.width));
  p.i1 = std::min(k.width - 1, clamp_ceil(umax, k.width));
  p.j0 = std::max(0, clamp_floor(vmin, k.height));
  p.j1 = std::min(k.height - 1, clamp_ceil(vmax, k.height));
}

std::vector<Primitive> Prepare(const ScannerScene& scene, const Eigen::Isometry3d& X_SensorBin,
                               const PinholeIntrinsics& k) {
  std::vector<Primitive> prims;
  for (const auto& s : scene.spheres) {
    const Eigen::Vector3d c = X_SensorBin * s.centre;
    Primitive p{Kind::kSphere, c, c, s.radius, s.label, 0, 0, 0, 0};
    ScreenBounds(c.array() - s.radius, c.array() + s.radius, k, p);
    prims.push_back(p);
  }
  for (const auto& cyl : scene.cylinders) {
    const Eigen::Vector3d a = X_SensorBin * cyl.start, b = X_SensorBin * cyl.end;
    Primitive p{Kind::kCylinder, a, b, cyl.radius, cyl.label, 0, 0, 0, 0};
    ScreenBounds(a.cwiseMin(b).array() - cyl.radius, a.cwiseMax(b).array() + cyl.radius, k, p);
    prims.push_back(p);
  }
  for (const auto& box : scene.boxes) {
    const Eigen::Vector3d lo = box.box.centre - box.box.half_size, hi = box.box.centre + box.box.half_size;
    Primitive p{Kind::kBox, lo, hi, 0.0, box.label, 0, 0, 0, 0};
    Eigen::Vector3d lo_S = Eigen::Vector3d::Constant(kInf), hi_S = -lo_S;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d q_S =
          X_SensorBin *
          Eigen::Vector3d((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
      lo_S = lo_S.cwiseMin(q_S);
      hi_S = hi_S.cwiseMax(q_S);
    }
    ScreenBounds(lo_S, hi_S, k, p);
    prims.push_back(p);
  }
  return prims;
}

struct RowOutput {
  Points points;
  std::vector<std::int32_t> labels;
  std::vector<std::uint32_t> pixels;
  std::uint64_t grazing = 0;
  std::uint64_t outliers = 0;
};

}  // namespace

void ScannerParams::Validate() const {
  auto require = [](bool ok, const std::string& field, double value, const std::string& expected) {
    if (!ok)
      throw InvalidArgument("scanner: " + field + " = " + std::to_string(value) + ": expected " + expected);
  };
  const PinholeIntrinsics& k = intrinsics;
  require(k.width >= 1 && k.width <= 20000, "intrinsics.width", k.width, "1..20000 px");
  require(k.height >= 1 && k.height <= 20000, "intrinsics.height", k.height, "1..20000 px");
  require(k.fx > 0.0 && std::isfinite(k.fx), "intrinsics.fx", k.fx, "> 0 px");
  require(k.fy > 0.0 && std::isfinite(k.fy), "intrinsics.fy", k.fy, "> 0 px");
  require(std::isfinite(k.cx), "intrinsics.cx", k.cx, "a finite number");
  require(std::isfinite(k.cy), "intrinsics.cy", k.cy, "a finite number");
  require(threads <= 1024, "threads", threads, "0 (all cores) .. 1024");
  require(depth_noise >= 0.0 && depth_noise < 0.1, "depth_noise", depth_noise, "0 ≤ σ < 0.1 m");
  require(max_incidence_angle > 0.0 && max_incidence_angle <= M_PI / 2, "max_incidence_angle",
          max_incidence_angle, "0 < angle ≤ π/2 rad");
  require(outlier_fraction >= 0.0 && outlier_fraction <= 1.0, "outlier_fraction", outlier_fraction,
          "in [0, 1]");
  require(min_range >= 0.0 && std::isfinite(min_range), "min_range", min_range, "≥ 0 m");
  require(max_range > min_range && std::isfinite(max_range), "max_range", max_range,
          "finite and > min_range");
  require(wall_thickness > 0.0 && wall_thickness <= 1.0, "wall_thickness", wall_thickness, "0 < t ≤ 1 m");
}

ScannerScene MakeScannerScene(const std::vector<TubeGeometry>& tubes_Bin, const BinSolids* bin) {
  ScannerScene scene;
  for (std::size_t k = 0; k < tubes_Bin.size(); ++k) {
    const TubeGeometry& tube = tubes_Bin[k];
    const auto label = static_cast<std::int32_t>(k);
    for (const TubeEdge& e : tube.edges) {
      scene.cylinders.push_back({tube.Node(e.node1).centre, tube.Node(e.node2).centre, e.radius, label});
    }
    for (const TubeNode& n : tube.nodes) {
      if (tube.IsJoint(n.id)) scene.spheres.push_back({n.centre, n.radius, label});
    }
  }
  if (bin != nullptr) {
    for (const AlignedBox& box : bin->boxes) scene.boxes.push_back({box, kBinLabel});
    scene.ground_z = bin->ground_z;
  }
  return scene;
}

ScanResult RenderScan(const ScannerScene& scene_Bin, const Eigen::Isometry3d& X_BinSensor,
                      const ScannerParams& params, std::uint64_t seed) {
  params.Validate();
  if (!X_BinSensor.matrix().allFinite()) throw InvalidArgument("scanner: X_BinSensor is not finite");
  const PinholeIntrinsics& k = params.intrinsics;
  const Eigen::Isometry3d X_SensorBin = X_BinSensor.inverse();
  const Eigen::Matrix3d R_BinSensor = X_BinSensor.linear();
  const Eigen::Vector3d p_BinSensor = X_BinSensor.translation();
  const std::vector<Primitive> prims = Prepare(scene_Bin, X_SensorBin, k);
  const double min_cos = std::cos(params.max_incidence_angle);

  std::vector<RowOutput> rows(k.height);
#pragma omp parallel for schedule(dynamic, 4) num_threads(ResolveThreads(params.threads))
  for (int j = 0; j < k.height; ++j) {
    std::vector<double> depth(k.width, kInf);
    std::vector<int> winner(k.width, -1);  // primitive index, −1 none, −2 ground
    std::vector<int> face(k.width, 0);
    const double y = (j - k.cy) / k.fy;
    auto direction = [&](int i) { return Eigen::Vector3d((i - k.cx) / k.fx, y, 1.0).normalized(); };

    for (std::size_t p = 0; p < prims.size(); ++p) {
      const Primitive& prim = prims[p];
      if (j < prim.j0 || j > prim.j1) continue;
      for (int i = prim.i0; i <= prim.i1; ++i) {
        const Eigen::Vector3d d = direction(i);
        double t = kInf;
        int axis = 0;
        switch (prim.kind) {
          case Kind::kSphere:
            t = RaySphere(Eigen::Vector3d::Zero(), d, prim.a, prim.radius);
            break;
          case Kind::kCylinder:
            t = RayCylinderSide(Eigen::Vector3d::Zero(), d, prim.a, prim.b, prim.radius);
            break;
          case Kind::kBox:
            t = RayAlignedBox(p_BinSensor, R_BinSensor * d, prim.a, prim.b, &axis);
            break;
        }
        if (t < depth[i]) {
          depth[i] = t;
          winner[i] = static_cast<int>(p);
          face[i] = axis;
        }
      }
    }
    if (scene_Bin.ground_z) {
      for (int i = 0; i < k.width; ++i) {
        const double t =
            RayPlane(p_BinSensor, R_BinSensor * direction(i), Eigen::Vector3d::UnitZ(), *scene_Bin.ground_z);
        if (t < depth[i]) {
          depth[i] = t;
          winner[i] = -2;
        }
      }
    }

    RowOutput& out = rows[j];
    std::mt19937_64 rng(DeriveSeed(seed, static_cast<std::uint64_t>(j)));
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (int i = 0; i < k.width; ++i) {
      const double t = depth[i];
      if (winner[i] == -1 || t < params.min_range || t > params.max_range) continue;
      const Eigen::Vector3d d = direction(i);
      // Surface normal at the hit, sensor frame.
      Eigen::Vector3d n;
      std::int32_t label = kBinLabel;
      if (winner[i] == -2) {
        n = X_SensorBin.linear() * Eigen::Vector3d::UnitZ();
      } else {
        const Primitive& prim = prims[winner[i]];
        label = prim.label;
        const Eigen::Vector3d hit = t * d;
        if (prim.kind == Kind::kSphere) {
          n = hit - prim.a;
        } else if (prim.kind == Kind::kCylinder) {
          const Eigen::Vector3d u = (prim.b - prim.a).normalized();
          const Eigen::Vector3d r = hit - prim.a;
          n = r - r.dot(u) * u;
        } else {
          n = X_SensorBin.linear().col(face[i]);
        }
      }
      const double n_norm = n.norm();
      if (!(n_norm > 0.0) || std::abs(d.dot(n)) < min_cos * n_norm) {
        ++out.grazing;
        continue;
      }
      double range = t;
      if (params.outlier_fraction > 0.0 && unit(rng) < params.outlier_fraction) {
        range = params.min_range + (t - params.min_range) * unit(rng);
        label = kOutlierLabel;
        ++out.outliers;
      } else if (params.depth_noise > 0.0) {
        range += params.depth_noise * noise(rng);
      }
      out.points.push_back((range * d).cast<float>());
      out.labels.push_back(label);
      out.pixels.push_back(static_cast<std::uint32_t>(j) * static_cast<std::uint32_t>(k.width) +
                           static_cast<std::uint32_t>(i));
    }
  }

  ScanResult result;
  std::size_t total = 0;
  for (const RowOutput& row : rows) total += row.points.size();
  result.points_Sensor.reserve(total);
  result.labels.reserve(total);
  result.pixels.reserve(total);
  for (RowOutput& row : rows) {
    result.points_Sensor.insert(result.points_Sensor.end(), row.points.begin(), row.points.end());
    result.labels.insert(result.labels.end(), row.labels.begin(), row.labels.end());
    result.pixels.insert(result.pixels.end(), row.pixels.begin(), row.pixels.end());
    result.grazing_dropped += row.grazing;
    result.outliers += row.outliers;
  }
  return result;
}

ScanResult ScanScene(const std::vector<TubeGeometry>& tubes_Bin, const CellConfig& cell,
                     const ScannerParams& params, std::uint64_t seed) {
  params.Validate();
  const BinSolids solids = MakeBinSolids(cell.bin, params.wall_thickness);
  ScannerScene scene = MakeScannerScene(tubes_Bin, params.render_bin ? &solids : nullptr);
  if (params.render_bin && !params.render_ground) scene.ground_z.reset();
  if (!params.render_bin && params.render_ground) scene.ground_z = solids.ground_z;
  return RenderScan(scene, cell.sensor.X_BinSensor, params, seed);
}

}  // namespace tubepick::physics
