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

TEST(WallWatch, ATubeWhoseTopReachesTheWallTopAtTheWallHangsOverIt) {
  v1::PlanPickResponse scan;  // every cylinder 1 cm in radius
  AddTubeAxis(scan, 7, {{-0.08, -0.10, 0.11}, {-0.065, -0.226, 0.183}, {-0.029, -0.304, 0.22}});
  AddTubeAxis(scan, 3, {{0.36, 0.0, 0.02}, {0.385, 0.1, 0.02}});  // on the floor along the +x wall
  AddTubeAxis(scan, 5, {{0.0, 0.0, 0.25}, {0.1, 0.0, 0.25}});     // high, in the middle
  AddTubeAxis(scan, 9, {{0.2, 0.0, 0.1}, {0.39, 0.2, 0.205}});    // 1 cm inside the +x wall's face
  AddTubeAxis(scan, 11, {{0.2, 0.0, 0.1}, {0.41, 0.2, 0.185}});   // past it, its top 0.5 cm below
  AddTubeAxis(scan, 12, {{0.2, 0.1, 0.1}, {0.405, 0.2, 0.201}});  // past it, above its top
  // Seed 14's trees before they fell: top 1 mm under the wall top 1.8 cm from the -y wall's face,
  // and 1.7 cm under it 2.7 cm from the +x wall's.
  AddTubeAxis(scan, 13, {{0.1, -0.2, 0.12}, {0.211, -0.282, 0.189}});
  AddTubeAxis(scan, 14, {{0.2, -0.149, 0.12}, {0.373, -0.149, 0.173}});
  AddTubeAxis(scan, 15, {{0.0, 0.2, 0.12}, {0.0, 0.25, 0.21}});    // 5 cm from the +y wall
  AddTubeAxis(scan, 16, {{-0.2, 0.0, 0.1}, {-0.37, 0.0, 0.165}});  // 3 cm from -x, its top 2.5 cm under
  AddTubeAxis(scan, 17,
              {{-0.2, 0.1, 0.1}, {-0.41, 0.1, 0.195}});  // past -x, its axis under the top, its top over
  const std::vector<TubeOverWall> over = TubesOverWalls(scan, kBin, 5, WallWatchParams{});
  std::vector<std::uint32_t> ids;
  for (const TubeOverWall& t : over) ids.push_back(t.tube_id);
  // By default only tops at or above the wall top, at or past its inner face.
  EXPECT_THAT(ids, ::testing::ElementsAre(7u, 12u, 17u));
  EXPECT_EQ(over[0].wall, "-y");
  EXPECT_TRUE(over[0].p_Bin.isApprox(Eigen::Vector3d(-0.029, -0.304, 0.22)));
  EXPECT_EQ(over[0].scan, 5u);
  EXPECT_EQ(Describe(over[0]), "over the -y wall at (-0.029, -0.304, 0.220) m, not seen again after scan 5");
  EXPECT_EQ(over[1].wall, "+x");
  // Within 2 cm of the top and 4 cm of the face: tubes leaning on a wall, seed 14's among them.
  WallWatchParams wide;
  wide.below_top = 0.02;
  wide.from_wall = 0.04;
  ids.clear();
  for (const TubeOverWall& t : TubesOverWalls(scan, kBin, 5, wide)) ids.push_back(t.tube_id);
  EXPECT_THAT(ids, ::testing::ElementsAre(7u, 9u, 11u, 12u, 13u, 14u, 17u));
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
