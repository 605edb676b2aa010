#include "core/modeling/segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/modeling/normals.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using testing::FloorTube;
using ::testing::HasSubstr;
using testing::RenderSyntheticCloud;
using testing::StraightTube;
using testing::SyntheticCloudParams;
using testing::SyntheticTube;

// A rendered scene in the bin frame with normals, floor (z < 4 mm) removed; label[i] is the
// tube of point i.
struct Scene {
  OrientedPoints cloud;
  std::vector<int> label;
};

Scene MakeScene(const std::vector<SyntheticTube>& tubes) {
  SyntheticCloudParams params;
  params.half_fov_x = 0.25;
  params.half_fov_y = 0.2;
  const testing::SyntheticCloud rendered = RenderSyntheticCloud(tubes, params);
  Points points_Bin;
  std::vector<int> label;
  for (std::size_t i = 0; i < rendered.points_Sensor.size(); ++i) {
    const Eigen::Vector3f p_Bin =
        (params.X_BinSensor * rendered.points_Sensor[i].cast<double>()).cast<float>();
    if (p_Bin.z() < 0.004f) continue;
    points_Bin.push_back(p_Bin);
    label.push_back(rendered.label[i]);
  }
  NormalParams normal_params;
  normal_params.radius = 0.005;
  Scene scene;
  scene.cloud =
      EstimateNormals(points_Bin, points_Bin, normal_params, params.X_BinSensor.translation().cast<float>());
  scene.label = std::move(label);
  return scene;
}

SegmentationParams TestParams() {
  SegmentationParams params;
  params.neighbours = 30;
  params.min_cluster_size = 200;
  return params;
}

// For each segment, the tube most of its points lie on; checks that it is nearly pure.
std::vector<int> MajorityLabels(const Scene& scene, const std::vector<Segment>& segments) {
  constexpr double kMinPurity = 0.99;
  std::vector<int> majority;
  for (const Segment& segment : segments) {
    std::map<int, std::size_t> count;
    for (std::uint32_t i : segment) ++count[scene.label[i]];
    const auto best = std::max_element(count.begin(), count.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    EXPECT_GE(static_cast<double>(best->second), kMinPurity * static_cast<double>(segment.size()));
    majority.push_back(best->first);
  }
  return majority;
}

void ExpectDisjointAndInRange(const std::vector<Segment>& segments, std::size_t cloud_size) {
  std::vector<int> seen(cloud_size, 0);
  for (const Segment& segment : segments) {
    for (std::uint32_t i : segment) {
      ASSERT_LT(i, cloud_size);
      EXPECT_EQ(seen[i]++, 0) << "index " << i << " is in two segments";
    }
  }
}

TEST(SegmentRegions, TwoSeparatedTubesGiveTwoSegments) {
  const Scene scene =
      MakeScene({FloorTube({{-0.15, -0.05}, {0.15, -0.05}}), FloorTube({{-0.1, 0.06}, {0.15, 0.1}})});
  const std::vector<Segment> segments = SegmentRegions(scene.cloud, TestParams());
  ASSERT_EQ(segments.size(), 2u);
  ExpectDisjointAndInRange(segments, scene.cloud.size());
  std::vector<int> labels = MajorityLabels(scene, segments);
  std::sort(labels.begin(), labels.end());
  EXPECT_EQ(labels, (std::vector<int>{0, 1}));
  // Each segment covers most of its tube (the grazing silhouette points may be left out).
  for (std::size_t s = 0; s < segments.size(); ++s) {
    const auto on_tube =
        std::count(scene.label.begin(), scene.label.end(), MajorityLabels(scene, {segments[s]})[0]);
    EXPECT_GT(static_cast<double>(segments[s].size()), 0.8 * static_cast<double>(on_tube));
  }
}

TEST(SegmentRegions, TubeCrossingOverAnotherSplitsTheLowerOne) {
  // Tube 0 lies on the floor along x; tube 1 crosses over it along y, resting on it.
  const Scene scene = MakeScene(
      {FloorTube({{-0.2, 0.0}, {0.2, 0.0}}), StraightTube({0.0, -0.15, 0.0375}, {0.02, 0.15, 0.0375})});
  const std::vector<Segment> segments = SegmentRegions(scene.cloud, TestParams());
  ExpectDisjointAndInRange(segments, scene.cloud.size());
  const std::vector<int> labels = MajorityLabels(scene, segments);
  EXPECT_EQ(std::count(labels.begin(), labels.end(), 0), 2)
      << "the lower tube is cut in two by the upper one";
  EXPECT_EQ(std::count(labels.begin(), labels.end(), 1), 1);
  EXPECT_EQ(segments.size(), 3u);
  // The two halves of the lower tube lie on either side of the upper one.
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (labels[s] != 0) continue;
    float min_x = std::numeric_limits<float>::max(), max_x = -min_x;
    for (std::uint32_t i : segments[s]) {
      min_x = std::min(min_x, scene.cloud.points[i].x());
      max_x = std::max(max_x, scene.cloud.points[i].x());
    }
    EXPECT_TRUE(max_x < 0.0f || min_x > 0.0f)
        << "segment " << s << " spans x in [" << min_x << ", " << max_x << "]";
  }
}

TEST(SegmentRegions, IsDeterministicWithAscendingIndices) {
  const Scene scene = MakeScene(
      {FloorTube({{-0.2, 0.0}, {0.2, 0.0}}), StraightTube({0.0, -0.15, 0.0375}, {0.02, 0.15, 0.0375})});
  const std::vector<Segment> first = SegmentRegions(scene.cloud, TestParams());
  const std::vector<Segment> second = SegmentRegions(scene.cloud, TestParams());
  EXPECT_EQ(first, second);
  for (const Segment& segment : first) EXPECT_TRUE(std::is_sorted(segment.begin(), segment.end()));
}

TEST(SegmentRegions, SkipsPointsWithNaNNormals) {
  Scene scene = MakeScene({FloorTube({{-0.15, 0.0}, {0.15, 0.0}})});
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  std::vector<bool> broken(scene.cloud.size(), false);
  for (std::size_t i = 0; i < scene.cloud.size(); i += 7) {
    scene.cloud.normals[i] = Eigen::Vector3f::Constant(kNaN);
    scene.cloud.curvature[i] = kNaN;
    broken[i] = true;
  }
  scene.cloud.curvature[1] = kNaN;  // a NaN curvature alone also excludes the point
  broken[1] = true;
  const std::vector<Segment> segments = SegmentRegions(scene.cloud, TestParams());
  ASSERT_EQ(segments.size(), 1u);
  for (std::uint32_t i : segments[0]) ASSERT_FALSE(broken[i]) << i;
  EXPECT_GT(segments[0].size(), scene.cloud.size() / 2);
}

TEST(SegmentRegions, DropsClustersOutsideTheSizeLimits) {
  const Scene scene = MakeScene({FloorTube({{-0.15, 0.0}, {0.15, 0.0}})});
  SegmentationParams params = TestParams();
  params.min_cluster_size = static_cast<std::uint32_t>(scene.cloud.size()) + 1;
  params.max_cluster_size = params.min_cluster_size + 1;
  EXPECT_TRUE(SegmentRegions(scene.cloud, params).empty());
  params.min_cluster_size = 1;
  params.max_cluster_size = 100;  // the tube's region is bigger; only small fragments remain
  for (const Segment& segment : SegmentRegions(scene.cloud, params)) EXPECT_LE(segment.size(), 100u);
}

TEST(SegmentRegions, SmoothnessThresholdSeparatesAFold) {
  // Two half-planes meeting at a 30° fold: one region with a loose threshold, two with 5°.
  OrientedPoints cloud;
  const Eigen::Vector3f n_left = Eigen::Vector3f(0.0f, 0.0f, 1.0f);
  const Eigen::Vector3f n_right = Eigen::Vector3f(-std::sin(0.5236f), 0.0f, std::cos(0.5236f));
  for (int i = -40; i < 40; ++i) {
    for (int j = -40; j < 40; ++j) {
      const float u = 0.0005f * static_cast<float>(i), v = 0.0005f * static_cast<float>(j);
      const bool right = i >= 0;
      cloud.points.push_back(right ? Eigen::Vector3f(u * std::cos(0.5236f), v, u * std::sin(0.5236f))
                                   : Eigen::Vector3f(u, v, 0.0f));
      cloud.normals.push_back(right ? n_right : n_left);
      cloud.curvature.push_back(0.0f);
    }
  }
  SegmentationParams params = TestParams();
  params.smoothness_threshold = 5.0 * M_PI / 180.0;
  EXPECT_EQ(SegmentRegions(cloud, params).size(), 2u);
  params.smoothness_threshold = 40.0 * M_PI / 180.0;
  EXPECT_EQ(SegmentRegions(cloud, params).size(), 1u);
}

TEST(SegmentRegions, HighCurvaturePointsJoinButDoNotGrow) {
  // A line of points with identical normals; only the first is a seed (low curvature), so the
  // region stops after its own neighbours.
  OrientedPoints cloud;
  for (int i = 0; i < 50; ++i) {
    cloud.points.emplace_back(0.001f * static_cast<float>(i), 0.0f, 0.0f);
    cloud.normals.emplace_back(0.0f, 0.0f, 1.0f);
    cloud.curvature.push_back(i == 0 ? 0.0f : 0.5f);
  }
  SegmentationParams params;
  params.neighbours = 5;
  params.min_cluster_size = 1;
  const std::vector<Segment> segments = SegmentRegions(cloud, params);
  ASSERT_FALSE(segments.empty());
  EXPECT_EQ(segments[0], (Segment{0, 1, 2, 3, 4}));
}

TEST(SegmentRegions, StopsWhenCancelled) {
  const Scene scene = MakeScene({FloorTube({{-0.15, 0.0}, {0.15, 0.0}})});
  StopToken token;
  token.RequestStop();
  EXPECT_THROW(SegmentRegions(scene.cloud, TestParams(), &token), Cancelled);
}

TEST(SegmentRegions, EmptyCloudGivesNoSegments) {
  EXPECT_TRUE(SegmentRegions(OrientedPoints{}, SegmentationParams{}).empty());
}

TEST(SegmentRegions, RejectsBadParametersNamingTheKey) {
  OrientedPoints cloud;
  cloud.points.assign(3, Eigen::Vector3f::Zero());
  cloud.normals.assign(3, Eigen::Vector3f::UnitZ());
  cloud.curvature.assign(3, 0.0f);
  auto error_of = [&](const SegmentationParams& params, const OrientedPoints& c) -> std::string {
    try {
      SegmentRegions(c, params);
    } catch (const InvalidArgument& e) {
      return e.what();
    }
    return "";
  };
  SegmentationParams params;
  params.neighbours = 0;
  EXPECT_THAT(error_of(params, cloud), HasSubstr("segmentation.neighbours"));
  params = SegmentationParams{};
  params.smoothness_threshold = 0.0;
  EXPECT_THAT(error_of(params, cloud), HasSubstr("segmentation.smoothness_threshold"));
  params = SegmentationParams{};
  params.min_cluster_size = 10;
  params.max_cluster_size = 5;
  EXPECT_THAT(error_of(params, cloud), HasSubstr("segmentation.min_cluster_size: 10"));
  OrientedPoints mismatched = cloud;
  mismatched.normals.pop_back();
  EXPECT_THAT(error_of(SegmentationParams{}, mismatched), HasSubstr("2 normals"));
}

}  // namespace
}  // namespace tubepick
