#include "core/modeling/bin_walls.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/common/errors.h"
#include "core/modeling/cloud_plausibility.h"

namespace tubepick {
namespace {

// The inner faces and the floor of a bin of inner size L × W × H as a scanner above it sees them:
// points every `step` metres (a 2 mm grid gives about 600 points per face and height band, as a
// 100 000-point sample of a 2.3 M-point scan does).
Points BinSurfaces(double L, double W, double H, double step = 0.004) {
  Points out;
  for (double z = 0.0; z <= H; z += step) {
    for (double x = -L / 2; x <= L / 2; x += step) {
      out.emplace_back(x, -W / 2, z);
      out.emplace_back(x, W / 2, z);
    }
    for (double y = -W / 2; y <= W / 2; y += step) {
      out.emplace_back(-L / 2, y, z);
      out.emplace_back(L / 2, y, z);
    }
  }
  for (double x = -L / 2; x <= L / 2; x += 2 * step) {
    for (double y = -W / 2; y <= W / 2; y += 2 * step) out.emplace_back(x, y, 0.0);
  }
  return out;
}

BinConfig Bin(double L, double W, double H = 0.2) {
  BinConfig bin;
  bin.inner_size = Eigen::Vector3d(L, W, H);
  return bin;
}

TEST(BinWalls, TheFacesOfTheCellsBinAreSeenWhereItPutsThem) {
  const BinWalls walls = FindBinWalls(BinSurfaces(0.8, 0.6, 0.2), Bin(0.8, 0.6), BinWallParams{});
  EXPECT_TRUE(walls.fit());
  const double expected[] = {-0.40, 0.40, -0.30, 0.30};
  for (int w = 0; w < 4; ++w) {
    ASSERT_TRUE(walls.seen[w].has_value()) << kWallNames[w];
    EXPECT_NEAR(*walls.seen[w], expected[w], 0.011) << kWallNames[w];
    EXPECT_DOUBLE_EQ(walls.expected[w], expected[w]);
  }
}

TEST(BinWalls, ABinSetLargerOrSmallerThanTheScannedOneDoesNotFit) {
  const Points scan = BinSurfaces(0.8, 0.6, 0.2);
  const BinWalls larger = FindBinWalls(scan, Bin(1.0, 0.8), BinWallParams{});
  EXPECT_FALSE(larger.fit());
  ASSERT_TRUE(larger.seen[1].has_value());
  EXPECT_NEAR(*larger.seen[1], 0.40, 0.011);
  EXPECT_THAT(DescribeBinWalls(larger),
              ::testing::HasSubstr("the +x wall at x = +0.400 m (the cell: +0.500 m)"));
  EXPECT_FALSE(FindBinWalls(scan, Bin(0.7, 0.6), BinWallParams{}).fit());  // the x walls 5 cm beyond
  EXPECT_TRUE(FindBinWalls(scan, Bin(0.86, 0.6), BinWallParams{}).fit());  // 3 cm: within 4 cm
  BinWallParams off;
  off.tolerance = 0.0;
  EXPECT_TRUE(FindBinWalls(scan, Bin(1.0, 0.8), off).fit());
}

TEST(BinWalls, TubesAtMidHeightAreNoWallAndTooFewPointsNoEvidence) {
  // No walls in the scan (a cloud of the floor and tubes only): nothing is seen, nothing misfits.
  Points tubes;
  for (double y = -0.25; y <= 0.25; y += 0.001) {
    for (double z = 0.09; z <= 0.115; z += 0.001) tubes.emplace_back(0.20f, y, z);  // a tube's side, one band
  }
  // And a tube standing upright 0.2 m from the centre, seen all round: it fills every band, but
  // one segment along the wall, no face.
  for (double a = 0.0; a < 6.28; a += 0.02) {
    for (double z = 0.0; z <= 0.2; z += 0.001)
      tubes.emplace_back(0.20 + 0.0125 * std::cos(a), 0.0125 * std::sin(a), z);
  }
  const BinWalls none = FindBinWalls(tubes, Bin(0.8, 0.6), BinWallParams{});
  EXPECT_TRUE(none.fit());
  for (const auto& seen : none.seen) EXPECT_FALSE(seen.has_value());
  // The walls at a coarse grid: too few points per band to be sure of anything.
  const BinWalls sparse = FindBinWalls(BinSurfaces(0.8, 0.6, 0.2, 0.05), Bin(1.0, 0.8), BinWallParams{});
  EXPECT_TRUE(sparse.fit());
}

TEST(CloudPlausibility, AScanWhoseWallsAreNotTheCellsIsNotPlausibleAndSaysWhich) {
  const Points scan = BinSurfaces(0.8, 0.6, 0.2);
  PlausibilityParams params;
  const CloudPlausibility right = CheckCloudAgainstCell(scan, Bin(0.8, 0.6), params);
  EXPECT_TRUE(right.plausible());
  const BinConfig larger = Bin(1.0, 0.8);
  const CloudPlausibility wrong = CheckCloudAgainstCell(scan, larger, params);
  EXPECT_TRUE(wrong.enough_inside);
  EXPECT_TRUE(wrong.floor_seen);
  EXPECT_FALSE(wrong.plausible());
  const std::string text =
      DescribeImplausibleCloud(wrong, larger, LengthUnit::kMetre, Eigen::Isometry3d::Identity(), params);
  EXPECT_THAT(text, ::testing::HasSubstr("cloud does not fit the cell's bin: the -x wall at x = -0.400 m"));
  EXPECT_THAT(text,
              ::testing::HasSubstr("Is bin.inner_size [1, 0.8, 0.2] m the bin's inner size, in metres? Set "
                                   "larger than the bin, the walls would be modeled as tubes"));
  // The same bin seen 6 cm off along x: the sensor pose.
  Points shifted = scan;
  for (auto& p : shifted) p.x() += 0.06f;
  const CloudPlausibility off = CheckCloudAgainstCell(shifted, Bin(0.8, 0.6), params);
  EXPECT_FALSE(off.plausible());
  EXPECT_THAT(
      DescribeImplausibleCloud(off, Bin(0.8, 0.6), LengthUnit::kMetre, Eigen::Isometry3d::Identity(), params),
      ::testing::HasSubstr("The walls are shifted, not resized: is the sensor pose right"));
  params.wall_tolerance = 0.0;
  EXPECT_TRUE(CheckCloudAgainstCell(scan, larger, params).plausible());
  params.wall_tolerance = -0.01;
  try {
    params.Validate();
    FAIL() << "a negative wall tolerance was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("modeling.plausibility.wall_tolerance"));
  }
}

}  // namespace
}  // namespace tubepick
