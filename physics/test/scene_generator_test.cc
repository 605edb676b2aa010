#include "physics/scene_generator.h"

#include <algorithm>
#include <limits>

#include <gtest/gtest.h>

#include "physics/virtual_scanner.h"

namespace tubepick::physics {
namespace {

/// Distance from p to the surface of a tube (cylinders and joint spheres), metres.
double DistanceToTube(const Eigen::Vector3d& p, const TubeGeometry& tube) {
  double best = std::numeric_limits<double>::infinity();
  for (const Cylinder& c : tube.Cylinders()) {
    const Eigen::Vector3d ab = c.end - c.start;
    const double s = (p - c.start).dot(ab) / ab.squaredNorm();
    if (s < 0.0 || s > 1.0) continue;  // beyond the side (no caps)
    best = std::min(best, std::abs((p - (c.start + s * ab)).norm() - c.radius));
  }
  for (const TubeNode& n : tube.nodes) {
    if (tube.IsJoint(n.id)) best = std::min(best, std::abs((p - n.centre).norm() - n.radius));
  }
  return best;
}

TEST(SceneGenerator, ScannedSceneMatchesItsGroundTruth) {
  SceneParams params;
  params.tube_count = 5;
  const DropResult scene = GenerateScene(params, 21);
  ASSERT_TRUE(scene.settled);
  const CellConfig cell;
  ScannerParams scanner;
  scanner.intrinsics = {960, 600, 800.0, 800.0, 479.5, 299.5};  // half resolution, same view
  const ScanResult scan = ScanScene(scene.tubes, cell, scanner, 21);
  std::vector<std::size_t> per_label(scene.tubes.size(), 0);
  std::size_t far = 0, on_tubes = 0;
  for (std::size_t i = 0; i < scan.labels.size(); ++i) {
    const int label = scan.labels[i];
    ASSERT_GE(label, kOutlierLabel);
    ASSERT_LT(label, static_cast<int>(scene.tubes.size()));
    if (label < 0) continue;
    ++per_label[label];
    ++on_tubes;
    const Eigen::Vector3d p_Bin = cell.sensor.X_BinSensor * scan.points_Sensor[i].cast<double>();
    far += DistanceToTube(p_Bin, scene.tubes[label]) > 4.0 * scanner.depth_noise;
  }
  for (std::size_t k = 0; k < per_label.size(); ++k) EXPECT_GT(per_label[k], 100u) << "tube " << k;
  EXPECT_LT(static_cast<double>(far), 1e-3 * on_tubes);
}

}  // namespace
}  // namespace tubepick::physics
