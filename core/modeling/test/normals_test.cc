#include "core/modeling/normals.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using testing::FloorTube;
using ::testing::HasSubstr;
using testing::RenderSyntheticCloud;
using testing::SyntheticCloudParams;

constexpr double kDeg = M_PI / 180.0;

// Renders the scene and returns the points in the bin frame; `crop_floor` drops z < 4 mm as the
// pipeline's crop box does.
Points RenderBin(const std::vector<testing::SyntheticTube>& tubes, const SyntheticCloudParams& params,
                 bool crop_floor) {
  const testing::SyntheticCloud cloud = RenderSyntheticCloud(tubes, params);
  Points points_Bin;
  for (const Eigen::Vector3f& p_Sensor : cloud.points_Sensor) {
    const Eigen::Vector3f p_Bin = (params.X_BinSensor * p_Sensor.cast<double>()).cast<float>();
    if (!crop_floor || p_Bin.z() >= 0.004f) points_Bin.push_back(p_Bin);
  }
  return points_Bin;
}

Eigen::Vector3f Viewpoint(const SyntheticCloudParams& params) {
  return params.X_BinSensor.translation().cast<float>();
}

double Percentile(std::vector<double> values, double q) {
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

double AngleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(EstimateNormals, PlaneNormalsFaceTheSensorWithZeroCurvature) {
  SyntheticCloudParams params;
  params.half_fov_x = params.half_fov_y = 0.05;  // a 11 cm square of floor
  const Points floor_Bin = RenderBin({}, params, /*crop_floor=*/false);
  ASSERT_GT(floor_Bin.size(), 10000u);

  const OrientedPoints result = EstimateNormals(floor_Bin, floor_Bin, NormalParams{}, Viewpoint(params));
  ASSERT_EQ(result.size(), floor_Bin.size());
  ASSERT_EQ(result.normals.size(), floor_Bin.size());
  ASSERT_EQ(result.curvature.size(), floor_Bin.size());
  std::vector<double> angles, curvatures;
  for (std::size_t i = 0; i < result.size(); ++i) {
    ASSERT_TRUE(result.normals[i].allFinite()) << i;
    EXPECT_NEAR(result.normals[i].norm(), 1.0, 1e-5);
    EXPECT_GT(result.normals[i].z(), 0.0f) << "normal " << i << " faces away from the sensor";
    EXPECT_EQ(result.points[i], floor_Bin[i]);
    angles.push_back(AngleBetween(result.normals[i].cast<double>(), Eigen::Vector3d::UnitZ()));
    curvatures.push_back(result.curvature[i]);
  }
  EXPECT_LT(Percentile(angles, 0.95), 1.5 * kDeg);
  EXPECT_LT(Percentile(angles, 1.0), 5.0 * kDeg);
  // Depth noise σ = 0.3 mm over a 5 mm disc: λ0/(λ0+λ1+λ2) ≈ σ²/(σ² + r²/2) ≈ 0.007.
  EXPECT_LT(Percentile(curvatures, 0.5), 0.01);
  EXPECT_LT(Percentile(curvatures, 1.0), 0.05);

  // Without noise the plane is exact.
  params.depth_noise = 0.0;
  const Points exact_Bin = RenderBin({}, params, false);
  const OrientedPoints exact = EstimateNormals(exact_Bin, exact_Bin, NormalParams{}, Viewpoint(params));
  for (std::size_t i = 0; i < exact.size(); ++i) {
    ASSERT_NEAR(exact.normals[i].z(), 1.0f, 1e-5f) << i;
    ASSERT_LT(exact.curvature[i], 1e-4f) << i;
  }
}

TEST(EstimateNormals, FlipsTowardsTheViewpoint) {
  SyntheticCloudParams params;
  params.half_fov_x = params.half_fov_y = 0.02;
  const Points floor_Bin = RenderBin({}, params, false);
  const OrientedPoints below =
      EstimateNormals(floor_Bin, floor_Bin, NormalParams{}, Eigen::Vector3f(0, 0, -1));
  for (const Eigen::Vector3f& n : below.normals) ASSERT_LT(n.z(), -0.99f);
}

TEST(EstimateNormals, TubeNormalsPointRadially) {
  constexpr double kRadius = 0.0125;
  constexpr double kHalfLength = 0.15;
  SyntheticCloudParams params;
  params.half_fov_x = params.half_fov_y = 0.18;
  const Points tube_Bin =
      RenderBin({FloorTube({{-kHalfLength, 0.0}, {kHalfLength, 0.0}}, kRadius)}, params, true);
  ASSERT_GT(tube_Bin.size(), 10000u);

  NormalParams normal_params;
  normal_params.radius = 0.005;
  const OrientedPoints result = EstimateNormals(tube_Bin, tube_Bin, normal_params, Viewpoint(params));
  std::vector<double> angles, curvatures;
  for (std::size_t i = 0; i < result.size(); ++i) {
    const Eigen::Vector3d p = result.points[i].cast<double>();
    if (std::abs(p.x()) > kHalfLength - 0.01) continue;  // away from the spherical caps
    ASSERT_TRUE(result.normals[i].allFinite()) << i;
    const Eigen::Vector3d radial = Eigen::Vector3d(0.0, p.y(), p.z() - kRadius).normalized();
    angles.push_back(AngleBetween(result.normals[i].cast<double>(), radial));
    curvatures.push_back(result.curvature[i]);
  }
  ASSERT_GT(angles.size(), 10000u);
  EXPECT_LT(Percentile(angles, 0.5), 1.5 * kDeg);
  EXPECT_LT(Percentile(angles, 0.9), 5.0 * kDeg);
  // A 5 mm patch of a 12.5 mm cylinder is nearly flat: low but non-zero surface variation.
  EXPECT_LT(Percentile(curvatures, 0.5), 0.05);
}

TEST(EstimateNormals, FewerThanThreeNeighboursGiveNaN) {
  // Two isolated points, a pair (2 neighbours each) and a triangle (3 neighbours each).
  const Points points = {{0.0f, 0.0f, 0.0f},   {1.0f, 0.0f, 0.0f},  {0.5f, 0.5f, 0.0f},
                         {0.501f, 0.5f, 0.0f}, {-0.5f, 0.0f, 0.0f}, {-0.499f, 0.0f, 0.0f},
                         {-0.5f, 0.001f, 0.0f}};
  const OrientedPoints result = EstimateNormals(points, points, NormalParams{}, Eigen::Vector3f(0, 0, 1));
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(result.normals[i].array().isNaN().all()) << i;
    EXPECT_TRUE(std::isnan(result.curvature[i])) << i;
  }
  for (int i = 4; i < 7; ++i) {
    ASSERT_TRUE(result.normals[i].allFinite()) << i;
    EXPECT_NEAR(result.normals[i].z(), 1.0f, 1e-5f) << i;
    EXPECT_NEAR(result.curvature[i], 0.0f, 1e-5f) << i;
  }
}

TEST(EstimateNormals, NonFinitePointsGetNaNAndAreNoNeighbours) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const Points points = {{0.0f, 0.0f, 0.0f}, {0.001f, 0.0f, 0.0f}, {0.0f, 0.001f, 0.0f}, {kNaN, 0.0f, 0.0f}};
  const OrientedPoints result = EstimateNormals(points, points, NormalParams{}, Eigen::Vector3f(0, 0, 1));
  EXPECT_TRUE(result.normals[3].array().isNaN().all());
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(result.normals[i].z(), 1.0f, 1e-5f) << i;
}

TEST(EstimateNormals, MaxNeighboursKeepsTheNearest) {
  // Around the query point: four points of the plane z = 0 at 1 mm, and a vertical line of
  // points 3–4 mm away in the plane x = 3 mm. With the nearest four only, the normal is z.
  Points surface = {{0.001f, 0.0f, 0.0f}, {-0.001f, 0.0f, 0.0f}, {0.0f, 0.001f, 0.0f}, {0.0f, -0.001f, 0.0f}};
  for (int i = 0; i < 20; ++i) {
    surface.push_back({0.003f, 0.0002f * static_cast<float>(i % 5), 0.0005f * static_cast<float>(i / 5)});
  }
  const Points query = {{0.0f, 0.0f, 0.0f}};
  NormalParams capped;
  capped.max_neighbours = 4;
  const OrientedPoints result = EstimateNormals(query, surface, capped, Eigen::Vector3f(0, 0, 1));
  ASSERT_TRUE(result.normals[0].allFinite());
  EXPECT_NEAR(result.normals[0].z(), 1.0f, 1e-5f);

  const OrientedPoints uncapped = EstimateNormals(query, surface, NormalParams{}, Eigen::Vector3f(0, 0, 1));
  ASSERT_TRUE(uncapped.normals[0].allFinite());
  EXPECT_LT(uncapped.normals[0].z(), 0.9f);
}

TEST(EstimateNormals, ResultPerPointDoesNotDependOnTheQuerySet) {
  SyntheticCloudParams params;
  params.half_fov_x = params.half_fov_y = 0.08;
  const Points tube_Bin = RenderBin({FloorTube({{-0.1, -0.02}, {0.1, 0.03}})}, params, true);
  NormalParams normal_params;
  normal_params.max_neighbours = 40;
  const OrientedPoints all = EstimateNormals(tube_Bin, tube_Bin, normal_params, Viewpoint(params));
  Points subset;
  std::vector<std::size_t> picked;
  for (std::size_t i = 0; i < tube_Bin.size(); i += 97) {
    subset.push_back(tube_Bin[i]);
    picked.push_back(i);
  }
  const OrientedPoints some = EstimateNormals(subset, tube_Bin, normal_params, Viewpoint(params));
  for (std::size_t j = 0; j < picked.size(); ++j) {
    EXPECT_EQ(some.normals[j], all.normals[picked[j]]) << j;
    EXPECT_EQ(some.curvature[j], all.curvature[picked[j]]) << j;
  }
  // And twice the same call gives the same bits.
  const OrientedPoints again = EstimateNormals(tube_Bin, tube_Bin, normal_params, Viewpoint(params));
  EXPECT_EQ(again.normals, all.normals);
}

TEST(EstimateNormals, StopsWhenCancelled) {
  SyntheticCloudParams params;
  params.half_fov_x = params.half_fov_y = 0.02;
  const Points floor_Bin = RenderBin({}, params, false);
  StopToken token;
  token.RequestStop();
  EXPECT_THROW(EstimateNormals(floor_Bin, floor_Bin, NormalParams{}, Viewpoint(params), &token), Cancelled);
}

TEST(EstimateNormals, EmptyInputGivesEmptyOutput) {
  const OrientedPoints result = EstimateNormals({}, {}, NormalParams{}, Eigen::Vector3f::Zero());
  EXPECT_EQ(result.size(), 0u);
  EXPECT_TRUE(result.normals.empty());
}

TEST(EstimateNormals, RejectsNonPositiveRadiusNamingIt) {
  NormalParams params;
  params.radius = 0.0;
  try {
    EstimateNormals({{0.0f, 0.0f, 0.0f}}, {{0.0f, 0.0f, 0.0f}}, params, Eigen::Vector3f::Zero());
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("normals.radius"));
  }
}

}  // namespace
}  // namespace tubepick
