#include "clients/cell/wall_watch.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
  AddTubeAxis(scan, 9, {{0.2, 0.0, 0.1}, {0.39, 0.2, 0.175}});    // at the +x wall, 2.5 cm below its top
  const std::vector<TubeOverWall> over = TubesOverWalls(scan, kBin, 5, WallWatchParams{});
  ASSERT_EQ(over.size(), 2u);
  EXPECT_EQ(over[0].tube_id, 7u);
  EXPECT_EQ(over[0].wall, "-y");
  EXPECT_TRUE(over[0].p_Bin.isApprox(Eigen::Vector3d(-0.029, -0.304, 0.22)));
  EXPECT_EQ(over[0].scan, 5u);
  EXPECT_EQ(Describe(over[0]), "over the -y wall at (-0.029, -0.304, 0.220) m, not seen again after scan 5");
  EXPECT_EQ(over[1].tube_id, 9u);
  EXPECT_EQ(over[1].wall, "+x");
}

TEST(WallWatch, ATubeOverAWallIsGoneWhenNoAxisOfTheNextScanComesNearAndNoAttemptTookIt) {
  const TubeOverWall hanging{7, {-0.029, -0.304, 0.22}, "-y", 5};
  v1::PlanPickResponse after;
  AddTubeAxis(after, 1, {{-0.029, -0.20, 0.15}, {0.1, -0.2, 0.15}});  // 12 cm away
  EXPECT_EQ(VanishedOverWalls({hanging}, after, {}, WallWatchParams{}).size(), 1u);
  EXPECT_TRUE(VanishedOverWalls({hanging}, after, {7}, WallWatchParams{}).empty()) << "an attempt took it";
  AddTubeAxis(after, 2, {{-0.03, -0.27, 0.19}, {-0.03, -0.29, 0.21}});  // still there, renumbered
  EXPECT_TRUE(VanishedOverWalls({hanging}, after, {}, WallWatchParams{}).empty());
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
}

}  // namespace
}  // namespace tubepick::cell
