#include "core/modeling/range_image.h"

#include <cmath>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/cell_config.h"
#include "core/common/errors.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
constexpr float kDepthTol = 1e-6f;
constexpr double kR = 0.0125;        // tube radius, metres
constexpr double kFloorCut = 0.004;  // bin-frame z below which rendered points are floor

// Sensor frame = bin frame: depth is z, angular coordinates are (x/z, y/z).
const Eigen::Isometry3d kIdentity = Eigen::Isometry3d::Identity();
constexpr double kPixel = 0.01;

// Two anchors fix the image to u, v ∈ [−0.1, 0.105] → 21 × 21 pixels; pixel i covers
// [−0.1 + 0.01·i, −0.1 + 0.01·(i+1)), its centre is at −0.095 + 0.01·i.
Points Anchors() { return {Eigen::Vector3f(-0.1f, -0.1f, 1.0f), Eigen::Vector3f(0.105f, 0.105f, 1.0f)}; }

double PixelCentre(int i) { return -0.095 + kPixel * i; }

// A point at depth z whose projection is the centre of pixel (i, j).
Eigen::Vector3f AtPixel(int i, int j, double z) {
  return Eigen::Vector3d(PixelCentre(i) * z, PixelCentre(j) * z, z).cast<float>();
}

// Endpoints at depths za, zb whose projections are 3 pixels left and right of pixel (10, 10)'s centre.
std::pair<Eigen::Vector3d, Eigen::Vector3d> GapAroundPixel10(double za = 1.0, double zb = 1.0) {
  const Eigen::Vector3d a(PixelCentre(7) * za, PixelCentre(10) * za, za);
  const Eigen::Vector3d b(PixelCentre(13) * zb, PixelCentre(10) * zb, zb);
  return {a, b};
}

// Renders tubes as the default sensor sees them and returns the non-floor points in the bin frame.
Points RenderBinPoints(const std::vector<testing::SyntheticTube>& tubes) {
  testing::SyntheticCloudParams cloud_params;
  cloud_params.half_fov_x = 0.3;
  cloud_params.half_fov_y = 0.3;
  const testing::SyntheticCloud cloud = testing::RenderSyntheticCloud(tubes, cloud_params);
  Points points_Bin;
  for (const Eigen::Vector3f& p_Sensor : cloud.points_Sensor) {
    const Eigen::Vector3d p_Bin = cloud_params.X_BinSensor * p_Sensor.cast<double>();
    if (p_Bin.z() >= kFloorCut) points_Bin.push_back(p_Bin.cast<float>());
  }
  return points_Bin;
}

TEST(RangeImage, BoundsFromCloudExtentAndNearestDepthPerPixel) {
  Points points = Anchors();
  points.push_back(AtPixel(4, 6, 0.8));
  points.push_back(AtPixel(4, 6, 0.7));  // same pixel, nearer: kept
  points.push_back(AtPixel(4, 6, 0.9));
  points.push_back(Eigen::Vector3f(0.0f, 0.0f, -1.0f));  // behind the sensor: ignored
  const RangeImage image(points, kIdentity, kPixel);
  EXPECT_EQ(image.width(), 21);
  EXPECT_EQ(image.height(), 21);
  EXPECT_NEAR(image.depth(4, 6), 0.7f, kDepthTol);
  EXPECT_NEAR(image.depth(0, 0), 1.0f, kDepthTol);
  EXPECT_NEAR(image.depth(20, 20), 1.0f, kDepthTol);
  EXPECT_TRUE(std::isinf(image.depth(6, 4)));
  EXPECT_TRUE(std::isinf(image.depth(10, 10)));
}

TEST(RangeImage, DepthIsOpticalZOfTheSensorFrame) {
  // Default mount: 1.1 m above the floor centre looking down, so depth = 1.1 − z_Bin.
  const Eigen::Isometry3d X_BinSensor = SensorConfig::DefaultX_BinSensor();
  const Points points_Bin = {Eigen::Vector3f(0.0f, 0.0f, 0.1f), Eigen::Vector3f(0.05f, 0.05f, 0.1f)};
  const RangeImage image(points_Bin, X_BinSensor, 0.002);
  ASSERT_GT(image.width(), 0);
  ASSERT_GT(image.height(), 0);
  // Optical x = bin x, optical y = −bin y: the first point is at u = 0 (left) and v = 0 (bottom
  // row), the second at u = 0.05 (right) and v = −0.05 (top row); both at depth 1.0.
  EXPECT_NEAR(image.depth(0, image.height() - 1), 1.0f, kDepthTol);
  EXPECT_NEAR(image.depth(image.width() - 1, 0), 1.0f, kDepthTol);
  EXPECT_TRUE(std::isinf(image.depth(0, 0)));
}

TEST(RangeImage, GapCoveredByANearerPixelAtTheMidpoint) {
  Points points = Anchors();
  points.push_back(AtPixel(10, 10, 0.9));
  const RangeImage image(points, kIdentity, kPixel);
  const auto [a, b] = GapAroundPixel10();
  EXPECT_TRUE(image.IsGapCovered(a, b, 0));
  EXPECT_TRUE(image.IsGapCovered(b, a, 0));
  // Nothing at the midpoint: empty pixels never cover.
  const RangeImage empty_gap(Anchors(), kIdentity, kPixel);
  EXPECT_FALSE(empty_gap.IsGapCovered(a, b, 2));
}

TEST(RangeImage, GapCoverNeedsDepthBelowTheDeeperEndpointMinusMargin) {
  Points points = Anchors();
  points.push_back(AtPixel(10, 10, 0.9));
  const RangeImage image(points, kIdentity, kPixel);
  {
    const auto [a, b] = GapAroundPixel10(1.0, 1.0);
    EXPECT_TRUE(image.IsGapCovered(a, b, 0, 0.05));
    EXPECT_FALSE(image.IsGapCovered(a, b, 0, 0.2));
  }
  {
    // The larger endpoint depth counts: 0.95 > 0.9 covers, 0.88 and 0.85 do not.
    const auto [a, b] = GapAroundPixel10(0.85, 0.95);
    EXPECT_TRUE(image.IsGapCovered(a, b, 0));
    const auto [c, d] = GapAroundPixel10(0.85, 0.88);
    EXPECT_FALSE(image.IsGapCovered(c, d, 0));
  }
  {
    // A pixel at exactly the endpoint depth is not "in front".
    Points level = Anchors();
    level.push_back(AtPixel(10, 10, 1.0));
    const RangeImage same_depth(level, kIdentity, kPixel);
    const auto [a, b] = GapAroundPixel10(1.0, 1.0);
    EXPECT_FALSE(same_depth.IsGapCovered(a, b, 0));
  }
}

TEST(RangeImage, WindowIsChebyshevAroundTheMidpointPixel) {
  Points points = Anchors();
  points.push_back(AtPixel(13, 8, 0.9));  // 3 pixels right, 2 up of the midpoint pixel (10, 10)
  const RangeImage image(points, kIdentity, kPixel);
  const auto [a, b] = GapAroundPixel10();
  EXPECT_FALSE(image.IsGapCovered(a, b, 2));
  EXPECT_TRUE(image.IsGapCovered(a, b, 3));
}

TEST(RangeImage, OutOfImageAndBehindSensorAreNotCovered) {
  Points points = Anchors();
  for (int i = 0; i < 21; ++i) {
    for (int j = 0; j < 21; ++j) points.push_back(AtPixel(i, j, 0.5));
  }
  const RangeImage image(points, kIdentity, kPixel);
  const auto [a, b] = GapAroundPixel10();
  ASSERT_TRUE(image.IsGapCovered(a, b, 0));
  // Midpoint projection right of the image (u = 0.3): not covered even with a large window.
  EXPECT_FALSE(image.IsGapCovered(Eigen::Vector3d(0.28, 0.0, 1.0), Eigen::Vector3d(0.32, 0.0, 1.0), 50));
  EXPECT_FALSE(image.IsGapCovered(Eigen::Vector3d(0.0, 0.0, -1.0), b, 2));
  // An empty image covers nothing.
  const RangeImage empty({}, kIdentity, kPixel);
  EXPECT_EQ(empty.width(), 0);
  EXPECT_EQ(empty.height(), 0);
  EXPECT_FALSE(empty.IsGapCovered(a, b, 2));
}

TEST(RangeImage, RejectsNonPositivePixelAngleNamingIt) {
  for (const double bad : {0.0, -0.002, std::nan("")}) {
    try {
      const RangeImage image(Anchors(), kIdentity, bad);
      FAIL() << "expected InvalidArgument for " << bad;
    } catch (const InvalidArgument& e) {
      EXPECT_THAT(e.what(), HasSubstr("pixel_angle"));
    }
  }
}

TEST(RangeImage, RenderedCrossingCoversTheLowerTubesHiddenPart) {
  // A tube on the floor along x, a second one lying across it along y.
  const testing::SyntheticTube lower = testing::FloorTube({{-0.25, 0.0}, {0.25, 0.0}}, kR);
  const testing::SyntheticTube upper = testing::StraightTube({0.0, -0.2, 3 * kR}, {0.0, 0.2, 3 * kR}, kR);
  const Eigen::Isometry3d X_BinSensor = SensorConfig::DefaultX_BinSensor();
  const Eigen::Vector3d a(-0.03, 0.0, kR), b(0.03, 0.0, kR);  // axis points beside the crossing

  const RangeImage crossing(RenderBinPoints({lower, upper}), X_BinSensor, 0.002);
  EXPECT_TRUE(crossing.IsGapCovered(a, b, 2));

  // The same gap between two separate tubes that end there: the floor (removed) shows through.
  const testing::SyntheticTube left = testing::FloorTube({{-0.25, 0.0}, {-0.03, 0.0}}, kR);
  const testing::SyntheticTube right = testing::FloorTube({{0.03, 0.0}, {0.25, 0.0}}, kR);
  const RangeImage apart(RenderBinPoints({left, right}), X_BinSensor, 0.002);
  EXPECT_FALSE(apart.IsGapCovered(a, b, 2));
}

}  // namespace
}  // namespace tubepick
