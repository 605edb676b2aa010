#include "core/modeling/filters.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

using Indices = std::vector<std::uint32_t>;

constexpr std::uint64_t kSeed = 42;

Indices Apply(const FilterStep& step, const Points& points, const FilterContext& context = {},
              const Points* normals = nullptr, std::uint64_t seed = kSeed) {
  return ApplyFilter(step, points, normals, context, seed);
}

bool IsStrictlyIncreasing(const Indices& indices) {
  return std::adjacent_find(indices.begin(), indices.end(), std::greater_equal<>()) == indices.end();
}

/// Uniform points in the box [lo, hi], from a seeded local RNG.
Points RandomPoints(std::size_t count, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                    std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Points points(count);
  for (Eigen::Vector3f& p : points) {
    for (int axis = 0; axis < 3; ++axis) p[axis] = lo[axis] + unit(rng) * (hi[axis] - lo[axis]);
  }
  return points;
}

/// A square grid of n×n points with the given spacing in the plane z = 0.
Points Grid(int n, float spacing) {
  Points points;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) points.emplace_back(i * spacing, j * spacing, 0.0f);
  }
  return points;
}

TEST(Filters, NamesAndNormalNeeds) {
  EXPECT_EQ(FilterName(CropBoxParams{}), "crop_box");
  EXPECT_EQ(FilterName(PassThroughParams{}), "pass_through");
  EXPECT_EQ(FilterName(VoxelGridParams{}), "voxel_grid");
  EXPECT_EQ(FilterName(RandomSampleParams{}), "random_sample");
  EXPECT_EQ(FilterName(RadiusOutlierParams{}), "radius_outlier");
  EXPECT_EQ(FilterName(StatisticalOutlierParams{}), "statistical_outlier");
  EXPECT_EQ(FilterName(PlaneRemovalParams{}), "plane_removal");
  EXPECT_TRUE(FilterNeedsNormals(PlaneRemovalParams{}));
  EXPECT_FALSE(FilterNeedsNormals(VoxelGridParams{}));
  EXPECT_FALSE(FilterNeedsNormals(CropBoxParams{}));
}

TEST(Filters, EmptyCloudGivesNoIndices) {
  const Points none;
  const Points no_normals;
  for (const FilterStep& step :
       std::vector<FilterStep>{CropBoxParams{}, PassThroughParams{}, VoxelGridParams{}, RandomSampleParams{},
                               RadiusOutlierParams{}, StatisticalOutlierParams{}, PlaneRemovalParams{}}) {
    EXPECT_TRUE(Apply(step, none, {}, &no_normals).empty()) << FilterName(step);
  }
}

TEST(CropBox, FromBinKeepsTheInterior) {
  FilterContext context;
  context.bin.inner_size = Eigen::Vector3d(0.80, 0.60, 0.20);
  CropBoxParams params;  // inset 5 mm, z from 4 mm to 0.20 + 0.30 m
  const Points points = {
      Eigen::Vector3f(0.0f, 0.0f, 0.05f),     // inside
      Eigen::Vector3f(0.399f, 0.0f, 0.05f),   // on the +x wall
      Eigen::Vector3f(0.0f, -0.298f, 0.05f),  // on the -y wall
      Eigen::Vector3f(0.1f, 0.1f, 0.001f),    // floor
      Eigen::Vector3f(0.1f, 0.1f, 0.45f),     // above the walls, within above_walls
      Eigen::Vector3f(0.1f, 0.1f, 0.55f),     // too high
      Eigen::Vector3f(0.39f, -0.29f, 0.01f),  // inside, near a corner
      Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.1f),
  };
  EXPECT_THAT(Apply(params, points, context), ElementsAre(0u, 4u, 6u));
}

TEST(CropBox, ExplicitCorners) {
  CropBoxParams params;
  params.from_bin = false;
  params.min = Eigen::Vector3d(-0.1, -0.1, 0.0);
  params.max = Eigen::Vector3d(0.1, 0.1, 0.1);
  const Points points = {Eigen::Vector3f(0.0f, 0.0f, 0.05f), Eigen::Vector3f(0.2f, 0.0f, 0.05f),
                         Eigen::Vector3f(0.05f, -0.05f, 0.09f), Eigen::Vector3f(0.0f, 0.0f, -0.01f)};
  EXPECT_THAT(Apply(params, points), ElementsAre(0u, 2u));
}

TEST(CropBox, InsetLargerThanTheBinIsAnError) {
  CropBoxParams params;
  params.inset_xy = 0.35;  // the bin is only 0.60 m wide
  try {
    Apply(params, {Eigen::Vector3f::Zero()});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("crop_box"));
    EXPECT_THAT(e.what(), HasSubstr("inset_xy 0.35"));
  }
}

TEST(PassThrough, SensorFrameDepth) {
  // Default mount: sensor 1.1 m above the floor looking down, so depth = 1.1 − z_bin.
  FilterContext context;
  context.X_BinSensor = SensorConfig::DefaultX_BinSensor();
  PassThroughParams params;  // z in the sensor frame, [0.1, 1.0] m (thesis Table 4.2)
  const Points points = {
      Eigen::Vector3f(0.0f, 0.0f, 0.0f),   // depth 1.1: too far
      Eigen::Vector3f(0.3f, 0.2f, 0.5f),   // depth 0.6
      Eigen::Vector3f(0.0f, 0.0f, 1.05f),  // depth 0.05: too near
      Eigen::Vector3f(-0.3f, 0.1f, 0.2f),  // depth 0.9
  };
  EXPECT_THAT(Apply(params, points, context), ElementsAre(1u, 3u));
}

TEST(PassThrough, SensorFrameMatchesExplicitTransform) {
  FilterContext context;
  context.X_BinSensor.linear() =
      (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  context.X_BinSensor.translation() = Eigen::Vector3d(0.2, -0.1, 1.0);
  PassThroughParams params;
  params.axis = Axis::kX;
  params.min = -0.1;
  params.max = 0.15;
  const Points points =
      RandomPoints(2000, Eigen::Vector3f(-0.4f, -0.3f, 0.0f), Eigen::Vector3f(0.4f, 0.3f, 0.3f), 7);
  Indices expected;
  const Eigen::Isometry3d X_SensorBin = context.X_BinSensor.inverse();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x_Sensor = (X_SensorBin * points[i].cast<double>()).x();
    if (x_Sensor >= params.min && x_Sensor <= params.max) expected.push_back(static_cast<std::uint32_t>(i));
  }
  ASSERT_GT(expected.size(), 100u);
  ASSERT_LT(expected.size(), points.size() - 100);
  EXPECT_EQ(Apply(params, points, context), expected);
}

TEST(PassThrough, BinFrame) {
  PassThroughParams params;
  params.frame = FilterFrame::kBin;
  params.axis = Axis::kY;
  params.min = 0.0;
  params.max = 0.1;
  const Points points = {Eigen::Vector3f(0.0f, -0.05f, 0.0f), Eigen::Vector3f(5.0f, 0.05f, -3.0f),
                         Eigen::Vector3f(0.0f, 0.15f, 0.0f)};
  EXPECT_THAT(Apply(params, points), ElementsAre(1u));
}

TEST(VoxelGrid, KeepsThePointNearestToTheCentroid) {
  VoxelGridParams params;
  params.leaf_size = 0.01;
  const Points points = {
      Eigen::Vector3f(0.001f, 0.001f, 0.001f),    // voxel (0, 0, 0), centroid 0.005
      Eigen::Vector3f(0.0052f, 0.0049f, 0.005f),  // nearest to that centroid
      Eigen::Vector3f(0.009f, 0.009f, 0.009f),    //
      Eigen::Vector3f(0.015f, 0.001f, 0.001f),    // voxel (1, 0, 0), alone
      Eigen::Vector3f(-0.001f, 0.001f, 0.001f),   // voxel (−1, 0, 0), alone
  };
  EXPECT_THAT(Apply(params, points), ElementsAre(1u, 3u, 4u));
}

TEST(VoxelGrid, KeepsOneUnmovedPointPerOccupiedVoxel) {
  VoxelGridParams params;
  params.leaf_size = 0.007;
  const Points points =
      RandomPoints(20000, Eigen::Vector3f(-0.05f, -0.03f, 0.0f), Eigen::Vector3f(0.05f, 0.03f, 0.04f), 3);
  using Key = std::tuple<std::int64_t, std::int64_t, std::int64_t>;
  auto key_of = [&](const Eigen::Vector3f& p) {
    const Eigen::Array3d v = (p.cast<double>().array() * (1.0 / params.leaf_size)).floor();
    return Key(static_cast<std::int64_t>(v.x()), static_cast<std::int64_t>(v.y()),
               static_cast<std::int64_t>(v.z()));
  };
  std::map<Key, std::vector<std::uint32_t>> members;
  for (std::size_t i = 0; i < points.size(); ++i)
    members[key_of(points[i])].push_back(static_cast<std::uint32_t>(i));

  const Indices kept = Apply(params, points);
  EXPECT_TRUE(IsStrictlyIncreasing(kept));
  ASSERT_EQ(kept.size(), members.size());
  std::set<Key> seen;
  for (std::uint32_t i : kept) {
    const Key key = key_of(points[i]);
    EXPECT_TRUE(seen.insert(key).second) << "two points kept in one voxel";
    // Brute force: i is the member nearest to its voxel's centroid.
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (std::uint32_t m : members[key]) centroid += points[m].cast<double>();
    centroid /= static_cast<double>(members[key].size());
    for (std::uint32_t m : members[key]) {
      EXPECT_LE((points[i].cast<double>() - centroid).norm(), (points[m].cast<double>() - centroid).norm());
    }
  }
}

TEST(RandomSample, KeepsExactlyCountIncreasingIndices) {
  RandomSampleParams params;
  params.count = 1000;
  const Points points(5000, Eigen::Vector3f::Zero());
  const Indices kept = Apply(params, points);
  EXPECT_EQ(kept.size(), 1000u);
  EXPECT_TRUE(IsStrictlyIncreasing(kept));
  EXPECT_LT(kept.back(), 5000u);
}

TEST(RandomSample, SameSeedSameResultDifferentSeedDifferentResult) {
  RandomSampleParams params;
  params.count = 500;
  const Points points(10000, Eigen::Vector3f::Zero());
  EXPECT_EQ(Apply(params, points, {}, nullptr, 1), Apply(params, points, {}, nullptr, 1));
  EXPECT_NE(Apply(params, points, {}, nullptr, 1), Apply(params, points, {}, nullptr, 2));
}

TEST(RandomSample, KeepsEverythingWhenCountExceedsSize) {
  RandomSampleParams params;
  params.count = 100;
  const Points points(7, Eigen::Vector3f::Zero());
  EXPECT_THAT(Apply(params, points), ElementsAre(0u, 1u, 2u, 3u, 4u, 5u, 6u));
}

TEST(RandomSample, IsUniform) {
  // Half of the sample should fall in the first half of the indices: within 5 σ of the
  // hypergeometric distribution (σ ≈ 47 here).
  constexpr std::size_t kPoints = 100000;
  constexpr std::uint32_t kCount = 10000;
  constexpr double kTolerance = 250.0;
  RandomSampleParams params;
  params.count = kCount;
  const Indices kept = Apply(params, Points(kPoints, Eigen::Vector3f::Zero()));
  const auto first_half =
      std::count_if(kept.begin(), kept.end(), [](std::uint32_t i) { return i < kPoints / 2; });
  EXPECT_NEAR(static_cast<double>(first_half), kCount / 2.0, kTolerance);
}

TEST(RadiusOutlier, RemovesIsolatedPoints) {
  Points points = Grid(10, 0.001f);  // 1 mm grid: every point has ≥ 5 others within 3 mm
  const std::size_t grid_size = points.size();
  points.emplace_back(0.1f, 0.1f, 0.0f);    // alone
  points.emplace_back(0.1f, 0.101f, 0.0f);  // a pair: one neighbour each
  points.emplace_back(-0.2f, 0.0f, 0.05f);  // alone
  RadiusOutlierParams params;
  params.radius = 0.003;
  params.min_neighbours = 5;
  const Indices kept = Apply(params, points);
  ASSERT_EQ(kept.size(), grid_size);
  for (std::size_t i = 0; i < grid_size; ++i) EXPECT_EQ(kept[i], i);
}

TEST(RadiusOutlier, CountsOtherPointsOnly) {
  // Three points 1 mm apart on a line: the middle one has two neighbours within 1.5 mm, the ends one.
  const Points points = {Eigen::Vector3f(0.0f, 0.0f, 0.0f), Eigen::Vector3f(0.001f, 0.0f, 0.0f),
                         Eigen::Vector3f(0.002f, 0.0f, 0.0f)};
  RadiusOutlierParams params;
  params.radius = 0.0015;
  params.min_neighbours = 2;
  EXPECT_THAT(Apply(params, points), ElementsAre(1u));
  params.min_neighbours = 1;
  EXPECT_THAT(Apply(params, points), ElementsAre(0u, 1u, 2u));
}

TEST(StatisticalOutlier, RemovesFarOutliers) {
  Points points = Grid(20, 0.001f);
  const std::size_t grid_size = points.size();
  points.emplace_back(0.5f, 0.0f, 0.0f);
  points.emplace_back(0.0f, -0.4f, 0.1f);
  points.emplace_back(0.01f, 0.01f, 0.3f);
  StatisticalOutlierParams params;
  params.neighbours = 10;
  params.stddev_mult = 3.0;
  const Indices kept = Apply(params, points);
  ASSERT_EQ(kept.size(), grid_size);
  EXPECT_EQ(kept.back(), grid_size - 1);
  EXPECT_TRUE(IsStrictlyIncreasing(kept));
}

TEST(StatisticalOutlier, MatchesBruteForceThreshold) {
  // Independent brute force of thesis Eq. 4.1: mean distance to the k nearest others, kept when
  // d <= μ + mult·σ (σ with Bessel's correction).
  constexpr int kNeighbours = 8;
  constexpr double kMult = 1.0;
  Points points =
      RandomPoints(400, Eigen::Vector3f(0.0f, 0.0f, 0.0f), Eigen::Vector3f(0.05f, 0.05f, 0.01f), 11);
  for (const Eigen::Vector3f& p :
       RandomPoints(20, Eigen::Vector3f(-0.1f, -0.1f, 0.0f), Eigen::Vector3f(0.15f, 0.15f, 0.1f), 12)) {
    points.push_back(p);
  }
  std::vector<double> mean_distance;
  for (const Eigen::Vector3f& p : points) {
    std::vector<double> d;
    for (const Eigen::Vector3f& q : points) d.push_back((p - q).cast<double>().norm());
    std::sort(d.begin(), d.end());  // d[0] = 0 is the point itself
    double sum = 0.0;
    for (int j = 1; j <= kNeighbours; ++j) sum += d[j];
    mean_distance.push_back(sum / kNeighbours);
  }
  const double n = static_cast<double>(points.size());
  double mu = 0.0;
  for (double d : mean_distance) mu += d / n;
  double variance = 0.0;
  for (double d : mean_distance) variance += (d - mu) * (d - mu) / (n - 1.0);
  const double threshold = mu + kMult * std::sqrt(variance);
  Indices expected;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (mean_distance[i] <= threshold) expected.push_back(static_cast<std::uint32_t>(i));
  }
  ASSERT_LT(expected.size(), points.size());  // the case removes something

  StatisticalOutlierParams params;
  params.neighbours = kNeighbours;
  params.stddev_mult = kMult;
  EXPECT_EQ(Apply(params, points), expected);
}

/// A floor with one tube lying on it, seen from the default mount, with analytic normals
/// (floor: +z; tube: radial from the centreline).
struct FloorScene {
  Points points_Bin;
  Points normals_Bin;
  std::vector<int> label;  // −1 floor, 0 tube
};

FloorScene MakeFloorScene() {
  const testing::SyntheticTube tube =
      testing::FloorTube({Eigen::Vector2d(-0.1, -0.02), Eigen::Vector2d(0.12, 0.03)});
  testing::SyntheticCloudParams params;
  params.pixel_angle = 0.002;
  params.half_fov_x = 0.2;
  params.half_fov_y = 0.15;
  params.floor_size = Eigen::Vector2d(0.4, 0.3);
  const testing::SyntheticCloud cloud = testing::RenderSyntheticCloud({tube}, params);
  FloorScene scene;
  const Eigen::Vector3d a = tube.centreline.front(), b = tube.centreline.back();
  for (std::size_t i = 0; i < cloud.points_Sensor.size(); ++i) {
    const Eigen::Vector3d p = params.X_BinSensor * cloud.points_Sensor[i].cast<double>();
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    if (cloud.label[i] >= 0) {
      const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      normal = (p - (a + t * (b - a))).normalized();
    }
    scene.points_Bin.push_back(p.cast<float>());
    scene.normals_Bin.push_back(normal.cast<float>());
    scene.label.push_back(cloud.label[i]);
  }
  return scene;
}

TEST(PlaneRemoval, RemovesTheFloorAndKeepsTheTube) {
  const FloorScene scene = MakeFloorScene();
  const auto floor_count = std::count(scene.label.begin(), scene.label.end(), -1);
  ASSERT_GT(floor_count, 10000);
  ASSERT_GT(scene.points_Bin.size() - floor_count, 500u);

  const PlaneRemovalParams params;  // thesis Table 4.2
  const Indices kept = Apply(params, scene.points_Bin, {}, &scene.normals_Bin);
  EXPECT_TRUE(IsStrictlyIncreasing(kept));
  std::size_t kept_floor = 0, kept_tube = 0;
  for (std::uint32_t i : kept) (scene.label[i] < 0 ? kept_floor : kept_tube)++;
  EXPECT_EQ(kept_floor, 0u);
  EXPECT_EQ(kept_tube, scene.points_Bin.size() - floor_count);
}

TEST(PlaneRemoval, SameSeedSameResult) {
  const FloorScene scene = MakeFloorScene();
  PlaneRemovalParams params;
  params.probability = 0.99;
  EXPECT_EQ(Apply(params, scene.points_Bin, {}, &scene.normals_Bin, 5),
            Apply(params, scene.points_Bin, {}, &scene.normals_Bin, 5));
}

TEST(PlaneRemoval, KeepsEverythingBelowMinInliers) {
  const FloorScene scene = MakeFloorScene();
  PlaneRemovalParams params;
  params.min_inliers = static_cast<std::uint32_t>(scene.points_Bin.size()) + 1;
  EXPECT_EQ(Apply(params, scene.points_Bin, {}, &scene.normals_Bin).size(), scene.points_Bin.size());
}

TEST(PlaneRemoval, IgnoresPlanesTooFarFromTheAxis) {
  // A plane tilted 0.3 rad about x, beyond eps_angle = 0.14 rad.
  const Eigen::Matrix3f R = Eigen::AngleAxisf(0.3f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  Points points;
  for (const Eigen::Vector3f& p : Grid(60, 0.003f)) points.push_back(R * p);
  const Points normals(points.size(), R * Eigen::Vector3f::UnitZ());
  PlaneRemovalParams params;
  params.min_inliers = 10;
  EXPECT_EQ(Apply(params, points, {}, &normals).size(), points.size());
  params.eps_angle = 0.35;  // now the plane qualifies
  EXPECT_TRUE(Apply(params, points, {}, &normals).empty());
}

TEST(PlaneRemoval, NeedsNormals) {
  const Points points(10, Eigen::Vector3f::Zero());
  try {
    Apply(PlaneRemovalParams{}, points);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("plane_removal: needs normals"));
  }
  const Points normals(3, Eigen::Vector3f::UnitZ());
  try {
    Apply(PlaneRemovalParams{}, points, {}, &normals);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("3 normals for 10 points"));
  }
}

TEST(Filters, PollTheStopToken) {
  StopToken stop;
  stop.RequestStop();
  try {
    ApplyFilter(VoxelGridParams{}, Points(10, Eigen::Vector3f::Zero()), nullptr, {}, kSeed, &stop);
    FAIL() << "expected Cancelled";
  } catch (const Cancelled& e) {
    EXPECT_THAT(e.what(), HasSubstr("filter voxel_grid"));
    EXPECT_FALSE(e.deadline_exceeded());
  }
}

struct InvalidCase {
  FilterStep step;
  std::string message;
};

std::vector<InvalidCase> InvalidCases() {
  std::vector<InvalidCase> cases;
  auto add = [&](FilterStep step, std::string message) {
    cases.push_back({std::move(step), std::move(message)});
  };
  {
    CropBoxParams p;
    p.inset_xy = -0.01;
    add(p, "crop_box.inset_xy: must be finite and >= 0, got -0.01");
  }
  {
    CropBoxParams p;
    p.from_bin = false;
    p.min = Eigen::Vector3d(0.0, 0.0, 0.2);
    p.max = Eigen::Vector3d(1.0, 1.0, 0.1);
    add(p, "crop_box.min: must be <= max [1, 1, 0.1] in every axis, got [0, 0, 0.2]");
  }
  {
    PassThroughParams p;
    p.min = 2.0;
    p.max = 1.0;
    add(p, "pass_through.min: must be <= max (1), got 2");
  }
  {
    VoxelGridParams p;
    p.leaf_size = 0.0;
    add(p, "voxel_grid.leaf_size: must be finite and > 0, got 0");
  }
  {
    VoxelGridParams p;
    p.leaf_size = std::numeric_limits<double>::quiet_NaN();
    add(p, "voxel_grid.leaf_size: must be finite and > 0, got nan");
  }
  {
    RandomSampleParams p;
    p.count = 0;
    add(p, "random_sample.count: must be > 0, got 0");
  }
  {
    RadiusOutlierParams p;
    p.radius = -0.007;
    add(p, "radius_outlier.radius: must be finite and > 0, got -0.007");
  }
  {
    StatisticalOutlierParams p;
    p.neighbours = 0;
    add(p, "statistical_outlier.neighbours: must be > 0, got 0");
  }
  {
    StatisticalOutlierParams p;
    p.stddev_mult = -1.0;
    add(p, "statistical_outlier.stddev_mult: must be finite and >= 0, got -1");
  }
  {
    PlaneRemovalParams p;
    p.distance_threshold = 0.0;
    add(p, "plane_removal.distance_threshold: must be finite and > 0, got 0");
  }
  {
    PlaneRemovalParams p;
    p.normal_distance_weight = 1.5;
    add(p, "plane_removal.normal_distance_weight: must be in [0, 1], got 1.5");
  }
  {
    PlaneRemovalParams p;
    p.axis = Eigen::Vector3d::Zero();
    add(p, "plane_removal.axis: must be a finite non-zero vector, got [0, 0, 0]");
  }
  {
    PlaneRemovalParams p;
    p.eps_angle = -0.1;
    add(p, "plane_removal.eps_angle: must be in [0, pi/2] radians, got -0.1");
  }
  {
    PlaneRemovalParams p;
    p.max_iterations = 0;
    add(p, "plane_removal.max_iterations: must be > 0, got 0");
  }
  {
    PlaneRemovalParams p;
    p.probability = 1.0;
    add(p, "plane_removal.probability: must be in (0, 1), got 1");
  }
  return cases;
}

TEST(ValidateFilter, NamesTheFieldAndTheValue) {
  for (const InvalidCase& c : InvalidCases()) {
    try {
      ValidateFilter(c.step, FilterName(c.step));
      ADD_FAILURE() << "expected InvalidArgument: " << c.message;
    } catch (const InvalidArgument& e) {
      EXPECT_EQ(std::string(e.what()), c.message);
    }
  }
}

TEST(ValidateFilter, UsesTheCallersKey) {
  VoxelGridParams p;
  p.leaf_size = -1.0;
  try {
    ValidateFilter(p, "modeling.filters[3]");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("modeling.filters[3].leaf_size: must be finite and > 0, got -1"));
  }
}

TEST(ValidateFilter, AcceptsTheDefaults) {
  for (const FilterStep& step :
       std::vector<FilterStep>{CropBoxParams{}, PassThroughParams{}, VoxelGridParams{}, RandomSampleParams{},
                               RadiusOutlierParams{}, StatisticalOutlierParams{}, PlaneRemovalParams{}}) {
    EXPECT_NO_THROW(ValidateFilter(step, FilterName(step))) << FilterName(step);
  }
}

TEST(ApplyFilter, ValidatesFirst) {
  RandomSampleParams p;
  p.count = 0;
  try {
    Apply(p, Points(3, Eigen::Vector3f::Zero()));
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("random_sample.count: must be > 0"));
  }
}

}  // namespace
}  // namespace tubepick
