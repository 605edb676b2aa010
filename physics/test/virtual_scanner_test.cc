#include "physics/virtual_scanner.h"

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <omp.h>

#include "core/common/errors.h"
#include "core/common/ray_intersect.h"

namespace tubepick::physics {
namespace {

using ::testing::HasSubstr;
constexpr double kSigma = 0.0003;
/// Float storage of a point ~1 m away.
constexpr double kFloatTol = 2e-6;

/// A small, fast scanner: 480 × 300 pixels with the default field of view.
ScannerParams SmallScanner() {
  ScannerParams params;
  params.intrinsics = {480, 300, 400.0, 400.0, 239.5, 149.5};
  params.outlier_fraction = 0.0;
  return params;
}

struct NoiseStats {
  double max_abs = 0.0;
  double within_4_sigma = 0.0;  // fraction
  double rms = 0.0;
};

NoiseStats Stats(const std::vector<double>& residuals) {
  NoiseStats s;
  std::size_t inside = 0;
  for (double r : residuals) {
    s.max_abs = std::max(s.max_abs, std::abs(r));
    inside += std::abs(r) <= 4.0 * kSigma;
    s.rms += r * r;
  }
  s.within_4_sigma = static_cast<double>(inside) / residuals.size();
  s.rms = std::sqrt(s.rms / residuals.size());
  return s;
}

void ExpectGaussianNoise(const std::vector<double>& residuals) {
  ASSERT_GT(residuals.size(), 1000u);
  const NoiseStats s = Stats(residuals);
  EXPECT_LE(s.max_abs, 6.0 * kSigma);
  EXPECT_GE(s.within_4_sigma, 0.999);
  EXPECT_NEAR(s.rms, kSigma, 0.1 * kSigma);
}

TEST(VirtualScanner, SphereAtTheRightDepth) {
  ScannerScene scene;
  const Eigen::Vector3d c_Bin(0.05, -0.03, 0.3);
  const double r = 0.05;
  scene.spheres.push_back({c_Bin, r, 0});
  const Eigen::Isometry3d X_BinSensor = SensorConfig::DefaultX_BinSensor();
  ScannerParams params = SmallScanner();

  params.depth_noise = 0.0;
  const ScanResult exact = RenderScan(scene, X_BinSensor, params, 1);
  ASSERT_GT(exact.points_Sensor.size(), 500u);
  for (std::size_t i = 0; i < exact.points_Sensor.size(); ++i) {
    const Eigen::Vector3d p_Bin = X_BinSensor * exact.points_Sensor[i].cast<double>();
    EXPECT_NEAR((p_Bin - c_Bin).norm(), r, kFloatTol);
    EXPECT_EQ(exact.labels[i], 0);
  }

  params.depth_noise = kSigma;
  params.intrinsics = ScannerParams{}.intrinsics;  // full resolution: many points for the statistics
  const ScanResult noisy = RenderScan(scene, X_BinSensor, params, 2);
  const Eigen::Vector3d c_Sensor = X_BinSensor.inverse() * c_Bin;
  std::vector<double> range_noise, surface_distance;
  for (const Eigen::Vector3f& p : noisy.points_Sensor) {
    const Eigen::Vector3d q = p.cast<double>();
    range_noise.push_back(q.norm() - RaySphere(Eigen::Vector3d::Zero(), q.normalized(), c_Sensor, r));
    surface_distance.push_back((q - c_Sensor).norm() - r);
  }
  ExpectGaussianNoise(range_noise);
  EXPECT_GE(Stats(surface_distance).within_4_sigma, 0.999);
  EXPECT_LE(Stats(surface_distance).max_abs, 6.0 * kSigma);
}

TEST(VirtualScanner, CylinderAtTheRightDepth) {
  ScannerScene scene;
  const Eigen::Vector3d a_Bin(-0.2, 0.05, 0.0125), b_Bin(0.15, -0.1, 0.08);
  const double r = 0.0125;
  scene.cylinders.push_back({a_Bin, b_Bin, r, 3});
  const Eigen::Isometry3d X_BinSensor = SensorConfig::DefaultX_BinSensor();
  ScannerParams params;
  params.outlier_fraction = 0.0;
  const ScanResult scan = RenderScan(scene, X_BinSensor, params, 3);
  const Eigen::Isometry3d X_SensorBin = X_BinSensor.inverse();
  const Eigen::Vector3d a = X_SensorBin * a_Bin, b = X_SensorBin * b_Bin;
  const Eigen::Vector3d u = (b - a).normalized();
  std::vector<double> range_noise, surface_distance;
  for (std::size_t i = 0; i < scan.points_Sensor.size(); ++i) {
    EXPECT_EQ(scan.labels[i], 3);
    const Eigen::Vector3d q = scan.points_Sensor[i].cast<double>();
    const Eigen::Vector3d w = q - a;
    surface_distance.push_back((w - w.dot(u) * u).norm() - r);
    range_noise.push_back(q.norm() - RayCylinderSide(Eigen::Vector3d::Zero(), q.normalized(), a, b, r));
  }
  ExpectGaussianNoise(range_noise);
  EXPECT_GE(Stats(surface_distance).within_4_sigma, 0.999);
}

/// Sensor at height `h` above the ground plane z = 0, optical axis tilted `tilt` from straight down.
Eigen::Isometry3d TiltedSensor(double h, double tilt) {
  const double s = std::sin(tilt), c = std::cos(tilt);
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear().col(0) = Eigen::Vector3d(0, -1, 0);   // x right
  X.linear().col(1) = Eigen::Vector3d(-c, 0, -s);  // y down
  X.linear().col(2) = Eigen::Vector3d(s, 0, -c);   // z forward
  X.translation() = Eigen::Vector3d(0, 0, h);
  return X;
}

double MaxIncidenceOnGround(const ScanResult& scan, const Eigen::Isometry3d& X_BinSensor) {
  double max_angle = 0.0;
  for (const Eigen::Vector3f& p : scan.points_Sensor) {
    const Eigen::Vector3d d_Bin = X_BinSensor.linear() * p.cast<double>().normalized();
    max_angle = std::max(max_angle, std::acos(std::abs(d_Bin.z())));
  }
  return max_angle;
}

TEST(VirtualScanner, GrazingIncidenceGivesNoReturn) {
  ScannerScene scene;
  scene.ground_z = 0.0;
  // Incidence on the ground ranges from ~49° to beyond the horizon across the image.
  const Eigen::Isometry3d X_BinSensor = TiltedSensor(0.5, 70.0 * M_PI / 180.0);
  ScannerParams params = SmallScanner();
  params.depth_noise = 0.0;
  params.max_range = 100.0;
  const ScanResult clipped = RenderScan(scene, X_BinSensor, params, 1);
  EXPECT_GT(clipped.grazing_dropped, 0u);
  const double max_clipped = MaxIncidenceOnGround(clipped, X_BinSensor);
  EXPECT_LE(max_clipped, params.max_incidence_angle + 1e-6);
  EXPECT_GT(max_clipped, params.max_incidence_angle - 1.0 * M_PI / 180.0);

  params.max_incidence_angle = 89.9 * M_PI / 180.0;
  const ScanResult wide = RenderScan(scene, X_BinSensor, params, 1);
  EXPECT_GT(MaxIncidenceOnGround(wide, X_BinSensor), 85.0 * M_PI / 180.0);
  EXPECT_GT(wide.points_Sensor.size(), clipped.points_Sensor.size());
}

/// Two straight tubes on the floor of the default bin.
std::vector<TubeGeometry> TwoTubes() {
  std::vector<TubeGeometry> tubes;
  const double r = 0.0125;
  for (const auto& [a, b] : {std::pair{Eigen::Vector3d(-0.25, -0.1, r), Eigen::Vector3d(0.1, -0.1, r)},
                             std::pair{Eigen::Vector3d(0.2, -0.2, r), Eigen::Vector3d(0.2, 0.2, r)}}) {
    TubeGeometry tube;
    tube.id = static_cast<int>(tubes.size()) + 1;
    tube.nodes = {{1, a, r}, {2, b, r}};
    TubeEdge e;
    e.name = "e_1_2";
    e.node1 = 1;
    e.node2 = 2;
    e.radius = r;
    SetEdgeFromNodes(tube, e);
    tube.edges.push_back(e);
    tubes.push_back(tube);
  }
  return tubes;
}

double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + s * ab)).norm();
}

TEST(VirtualScanner, LabelsMatchTheSurfaceHit) {
  const std::vector<TubeGeometry> tubes = TwoTubes();
  const CellConfig cell;
  ScannerParams params;
  params.depth_noise = 0.0;
  params.outlier_fraction = 0.0;
  const ScanResult scan = ScanScene(tubes, cell, params, 1);
  ASSERT_EQ(scan.labels.size(), scan.points_Sensor.size());
  ASSERT_EQ(scan.pixels.size(), scan.points_Sensor.size());
  const double hx = 0.4, hy = 0.3, h = 0.2, t = params.wall_thickness;
  constexpr double kTol = 1e-5;
  std::size_t counts[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < scan.points_Sensor.size(); ++i) {
    const Eigen::Vector3d p = cell.sensor.X_BinSensor * scan.points_Sensor[i].cast<double>();
    const int label = scan.labels[i];
    ASSERT_GE(label, -1);
    ASSERT_LE(label, 1);
    ++counts[label + 1];
    if (label >= 0) {
      const TubeGeometry& tube = tubes[label];
      EXPECT_NEAR(DistanceToSegment(p, tube.Node(1).centre, tube.Node(2).centre), tube.edges[0].radius, kTol);
    } else {
      const bool floor =
          std::abs(p.z()) < kTol && std::abs(p.x()) <= hx + kTol && std::abs(p.y()) <= hy + kTol;
      const bool wall_top = std::abs(p.z() - h) < kTol;
      const bool inner_wall =
          (std::abs(std::abs(p.x()) - hx) < kTol || std::abs(std::abs(p.y()) - hy) < kTol) && p.z() > -kTol &&
          p.z() < h + kTol;
      const bool ground = std::abs(p.z() + t) < kTol &&
                          (std::abs(p.x()) >= hx + t - kTol || std::abs(p.y()) >= hy + t - kTol);
      EXPECT_TRUE(floor || wall_top || inner_wall || ground) << p.transpose();
    }
  }
  EXPECT_GT(counts[0], 1000000u);  // bin and ground
  EXPECT_GT(counts[1], 5000u);     // 35 cm tube
  EXPECT_GT(counts[2], 5000u);     // 40 cm tube
  // The pixel under the top of tube 0's middle sees tube 0.
  const Eigen::Vector3d top_Sensor = cell.sensor.X_BinSensor.inverse() * Eigen::Vector3d(-0.075, -0.1, 0.025);
  const auto& k = params.intrinsics;
  const int col = static_cast<int>(std::lround(k.fx * top_Sensor.x() / top_Sensor.z() + k.cx));
  const int row = static_cast<int>(std::lround(k.fy * top_Sensor.y() / top_Sensor.z() + k.cy));
  const auto it =
      std::find(scan.pixels.begin(), scan.pixels.end(), static_cast<std::uint32_t>(row * k.width + col));
  ASSERT_NE(it, scan.pixels.end());
  EXPECT_EQ(scan.labels[it - scan.pixels.begin()], 0);
}

TEST(VirtualScanner, OutliersAreLabelledAndInFrontOfTheSurface) {
  const CellConfig cell;
  ScannerParams params = SmallScanner();
  params.depth_noise = 0.0;
  params.outlier_fraction = 0.01;
  const ScanResult scan = ScanScene(TwoTubes(), cell, params, 4);
  std::size_t outliers = 0;
  for (std::size_t i = 0; i < scan.labels.size(); ++i) {
    if (scan.labels[i] != kOutlierLabel) continue;
    ++outliers;
    const Eigen::Vector3d p = cell.sensor.X_BinSensor * scan.points_Sensor[i].cast<double>();
    EXPECT_GE(p.z(), -params.wall_thickness - kFloatTol);  // not behind the ground
    EXPECT_GE(scan.points_Sensor[i].norm(), params.min_range - kFloatTol);
  }
  EXPECT_EQ(outliers, scan.outliers);
  const double expected = params.outlier_fraction * scan.labels.size();
  EXPECT_NEAR(static_cast<double>(outliers), expected, 5.0 * std::sqrt(expected));
}

TEST(VirtualScanner, DeterministicForASeedWhateverTheThreadCount) {
  const CellConfig cell;
  ScannerParams params = SmallScanner();
  params.outlier_fraction = 0.001;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const ScanResult one = ScanScene(TwoTubes(), cell, params, 7);
  omp_set_num_threads(std::max(2, threads));
  const ScanResult many = ScanScene(TwoTubes(), cell, params, 7);
  omp_set_num_threads(threads);
  const ScanResult other = ScanScene(TwoTubes(), cell, params, 8);
  ASSERT_EQ(one.points_Sensor.size(), many.points_Sensor.size());
  EXPECT_TRUE(one.points_Sensor == many.points_Sensor);
  EXPECT_EQ(one.labels, many.labels);
  EXPECT_FALSE(one.points_Sensor == other.points_Sensor);
}

TEST(VirtualScanner, InvalidParamsAreNamed) {
  ScannerParams params;
  params.intrinsics.fx = -1.0;
  try {
    RenderScan(ScannerScene{}, SensorConfig::DefaultX_BinSensor(), params, 1);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("intrinsics.fx = -1"));
  }
}

}  // namespace
}  // namespace tubepick::physics
