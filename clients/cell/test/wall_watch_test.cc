#include "clients/cell/wall_watch.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "clients/cell/test/scripted_cell.h"
#include "core/common/errors.h"

namespace tubepick::cell {
namespace {

using testing::AddTubeAxis;

// The thesis bin: 0.8 x 0.6 m inside, walls 0.2 m high.
const BinConfig kBin;

TEST(WallWatch, ATubeRisingOverTheWallTopHangsOverIt) {
  v1::PlanPickResponse scan;
  AddTubeAxis(scan, 7, {{-0.08, -0.10, 0.11}, {-0.065, -0.226, 0.183}, {-0.029, -0.304, 0.22}});
  AddTubeAxis(scan, 3, {{0.36, 0.0, 0.02}, {0.385, 0.1, 0.02}});  // on the floor along the +x wall
  AddTubeAxis(scan, 5, {{0.0, 0.0, 0.25}, {0.1, 0.0, 0.25}});     // high, in the middle
  AddTubeAxis(scan, 9, {{0.2, 0.0, 0.1}, {0.39, 0.2, 0.205}});    // 1 cm inside the +x wall's face
  AddTubeAxis(scan, 11, {{0.2, 0.0, 0.1}, {0.41, 0.2, 0.19}});    // past it, 1 cm below its top
  AddTubeAxis(scan, 12, {{0.2, 0.1, 0.1}, {0.405, 0.2, 0.201}});  // past it, above its top
  const std::vector<TubeOverWall> over = TubesOverWalls(scan, kBin, 5, WallWatchParams{});
  ASSERT_EQ(over.size(), 2u);
  EXPECT_EQ(over[0].tube_id, 7u);
  EXPECT_EQ(over[0].wall, "-y");
  EXPECT_TRUE(over[0].p_Bin.isApprox(Eigen::Vector3d(-0.029, -0.304, 0.22)));
  EXPECT_EQ(over[0].scan, 5u);
  EXPECT_EQ(Describe(over[0]), "over the -y wall at (-0.029, -0.304, 0.220) m, not seen again after scan 5");
  EXPECT_EQ(over[1].tube_id, 12u);
  EXPECT_EQ(over[1].wall, "+x");
  // Leaning on the inner face within 3 cm of its top counts when the limits say so.
  WallWatchParams wide;
  wide.below_top = 0.03;
  wide.from_wall = 0.03;
  EXPECT_EQ(TubesOverWalls(scan, kBin, 5, wide).size(), 4u);
}

/// A capture of `points_Bin` by the default sensor (1.1 m above the floor, looking down), in `unit`.
devices::Capture CaptureOf(const std::vector<Eigen::Vector3d>& points_Bin,
                           LengthUnit unit = LengthUnit::kMetre) {
  devices::Capture c;
  c.unit = unit;
  const double scale = unit == LengthUnit::kMillimetre ? 1000.0 : 1.0;
  for (const Eigen::Vector3d& p : points_Bin)
    c.points_Sensor.push_back((scale * (c.X_BinSensor.inverse() * p)).cast<float>());
  return c;
}

/// n points on a 1 cm ring about `centre` in the x-z plane (a tube's surface about its axis).
std::vector<Eigen::Vector3d> Ring(const Eigen::Vector3d& centre, int n) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    out.push_back(centre + 0.01 * Eigen::Vector3d(std::cos(a), 0.0, std::sin(a)));
  }
  return out;
}

/// The -y wall's own points near x: its inner face and its top.
std::vector<Eigen::Vector3d> WallNear(double x) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 40; ++i) {
    out.push_back({x + 0.001 * i, -0.3, 0.19 + 0.0002 * i});   // inner face
    out.push_back({x + 0.001 * i, -0.305 - 0.0002 * i, 0.2});  // top
  }
  return out;
}

TEST(WallWatch, ATubeOverAWallIsGoneWhenTheNextCloudHasNoPointThereButTheWallsOwn) {
  const TubeOverWall hanging{7, {-0.029, -0.304, 0.22}, "-y", 5};
  std::vector<Eigen::Vector3d> gone = WallNear(-0.04);
  for (const Eigen::Vector3d& p : Ring({0.1, -0.2, 0.15}, 40)) gone.push_back(p);  // another tube, 15 cm away
  EXPECT_EQ(PointsNear(CaptureOf(gone), hanging.p_Bin, 0.03, kBin), 0u);
  EXPECT_EQ(VanishedOverWalls({hanging}, CaptureOf(gone), kBin, {}, WallWatchParams{}).size(), 1u);
  EXPECT_TRUE(VanishedOverWalls({hanging}, CaptureOf(gone), kBin, {7}, WallWatchParams{}).empty())
      << "an attempt took it";

  std::vector<Eigen::Vector3d> there = gone;
  for (const Eigen::Vector3d& p : Ring({-0.03, -0.29, 0.215}, 40)) there.push_back(p);  // still there
  EXPECT_EQ(PointsNear(CaptureOf(there), hanging.p_Bin, 0.03, kBin), 40u);
  EXPECT_TRUE(VanishedOverWalls({hanging}, CaptureOf(there), kBin, {}, WallWatchParams{}).empty());
  EXPECT_TRUE(
      VanishedOverWalls({hanging}, CaptureOf(there, LengthUnit::kMillimetre), kBin, {}, WallWatchParams{})
          .empty())
      << "a cloud in millimetres";
}

TEST(WallWatch, OffWatchesNothingAndBadLimitsAreNamed) {
  v1::PlanPickResponse scan;
  AddTubeAxis(scan, 7, {{-0.08, -0.10, 0.11}, {-0.029, -0.304, 0.22}});
  WallWatchParams off;
  off.enabled = false;
  EXPECT_TRUE(TubesOverWalls(scan, kBin, 0, off).empty());
  WallWatchParams bad;
  bad.gone_distance = 0.0;
  EXPECT_THROW(bad.Validate(), InvalidArgument);
  bad = WallWatchParams{};
  bad.min_points = 0;
  EXPECT_THROW(bad.Validate(), InvalidArgument);
}

}  // namespace
}  // namespace tubepick::cell
