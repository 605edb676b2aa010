#include "core/params.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseParams(yaml, ProfileParams("fast"));
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(Params, BothProfilesAreValid) {
  for (const auto& name : ProfileNames()) EXPECT_NO_THROW(ProfileParams(name).Validate()) << name;
  EXPECT_THROW(ProfileParams("turbo"), InvalidArgument);
}

TEST(Params, ThesisProfileHasTableValues) {
  const ModelingParams p = ProfileParams("thesis").modeling;
  EXPECT_EQ(p.segmentation.neighbours, 77u);
  EXPECT_EQ(p.segmentation.min_cluster_size, 100u);
  EXPECT_DOUBLE_EQ(p.cylinders.safety_length, 0.01);
  EXPECT_DOUBLE_EQ(p.cylinders.safety_radius, 0.02);
  EXPECT_DOUBLE_EQ(p.cylinders.distance_threshold, 0.02);
  EXPECT_DOUBLE_EQ(p.joining.max_tube_length, 0.60);
  EXPECT_DOUBLE_EQ(p.joining.max_distance, 0.10);                      // Table 4.3
  EXPECT_DOUBLE_EQ(p.joining.max_length_share, 0.0);                   // the thesis knows no tube length
  EXPECT_NEAR(p.joining.angular_weight * M_PI / 180.0, 0.001, 1e-12);  // 0.001 m per degree
  EXPECT_EQ(p.normals.search_surface, SearchSurface::kRaw);
  ASSERT_EQ(p.filters.size(), 7u);
  EXPECT_EQ(std::get<RandomSampleParams>(p.filters[1]).count, 100000u);
  EXPECT_EQ(std::get<RandomSampleParams>(p.filters[4]).count, 25000u);
  EXPECT_EQ(std::get<StatisticalOutlierParams>(p.filters[6]).neighbours, 100u);
}

TEST(Params, TheFastProfileJoinsHiddenGapsUpTo18CentimetresWithinTheCellsTubeLength) {
  const JoiningParams& j = ProfileParams("fast").modeling.joining;
  EXPECT_DOUBLE_EQ(j.max_distance, 0.18);
  EXPECT_DOUBLE_EQ(j.max_length_share, 1.04);
  EXPECT_DOUBLE_EQ(j.max_tube_length, 0.60);
}

TEST(Params, TheResolutionRotatesTheThesis45DegreesOr55InTheFastProfileThenAboutThePerpendicular) {
  EXPECT_NEAR(ProfileParams("thesis").wrench.rotation_angle, 45.0 * M_PI / 180.0, 1e-15);  // Table 5.3
  EXPECT_NEAR(ProfileParams("fast").wrench.rotation_angle, 55.0 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(ProfileParams("thesis").wrench.variant, ResolutionVariant::kTorqueAxis);  // §5.2.6
  EXPECT_EQ(ProfileParams("fast").wrench.variant, ResolutionVariant::kTorqueAxisThenPerpendicular);
  EXPECT_EQ(ProfileParams("thesis").wrench.force_tolerance_share, 0.0);  // Algorithm 3's F_tol alone
  EXPECT_EQ(ProfileParams("fast").wrench.force_tolerance_share, 0.2);
}

TEST(Params, DumpRoundTrips) {
  for (const auto& name : ProfileNames()) {
    const Params p = ProfileParams(name);
    const std::string yaml = DumpParams(p);
    const Params q = ParseParams(yaml, ProfileParams(name == "fast" ? "thesis" : "fast"));
    EXPECT_EQ(DumpParams(q), yaml) << name;
  }
}

TEST(Params, OverridesOnlyGivenKeys) {
  const Params p = ParseParams("modeling:\n  cylinders:\n    min_inliers: 80\n", ProfileParams("fast"));
  EXPECT_EQ(p.modeling.cylinders.min_inliers, 80u);
  EXPECT_EQ(p.modeling.cylinders.max_iterations, ProfileParams("fast").modeling.cylinders.max_iterations);
}

TEST(Params, FilterListReplacesThePipeline) {
  const Params p = ParseParams(
      "modeling:\n  filters:\n    - voxel_grid: {leaf_size: 0.004}\n    - random_sample: {count: 1000}\n",
      ProfileParams("fast"));
  ASSERT_EQ(p.modeling.filters.size(), 2u);
  EXPECT_DOUBLE_EQ(std::get<VoxelGridParams>(p.modeling.filters[0]).leaf_size, 0.004);
  EXPECT_EQ(std::get<RandomSampleParams>(p.modeling.filters[1]).count, 1000u);
}

TEST(Params, UnknownKeysAreErrorsNamingThem) {
  EXPECT_THAT(ErrorOf("modeling:\n  cylinders:\n    min_inlier: 80\n"),
              HasSubstr("modeling.cylinders.min_inlier"));
  EXPECT_THAT(ErrorOf("planing: {}\n"), HasSubstr("planing"));
  EXPECT_THAT(ErrorOf("modeling:\n  filters:\n    - median: {}\n"), HasSubstr("unknown filter 'median'"));
  EXPECT_THAT(ErrorOf("modeling:\n  filters:\n    - voxel_grid: {leaf: 0.1}\n"),
              HasSubstr("modeling.filters[0].voxel_grid.leaf"));
}

TEST(Params, OutOfRangeValuesNameTheKey) {
  EXPECT_THAT(ErrorOf("modeling:\n  cylinders:\n    min_radius: 0.02\n    max_radius: 0.01\n"),
              HasSubstr("modeling.cylinders.min_radius"));
  EXPECT_THAT(ErrorOf("modeling:\n  cylinders:\n    normal_distance_weight: 1.5\n"),
              HasSubstr("normal_distance_weight"));
  EXPECT_THAT(ErrorOf("modeling:\n  normals:\n    radius: -1\n"), HasSubstr("modeling.normals.radius"));
  EXPECT_THAT(ErrorOf("modeling:\n  segmentation:\n    neighbours: -3\n"),
              HasSubstr("modeling.segmentation.neighbours"));
  EXPECT_THAT(ErrorOf("modeling:\n  joining:\n    strategy: random\n"),
              HasSubstr("modeling.joining.strategy"));
  EXPECT_THAT(ErrorOf("modeling:\n  normals:\n    radius: abc\n"), HasSubstr("expected a number"));
  EXPECT_THAT(ErrorOf("modeling:\n  filters:\n    - random_sample: {count: 0}\n"), HasSubstr("count"));
}

TEST(Params, AForceToleranceShareOutOfRangeNamesTheKey) {
  EXPECT_THAT(ErrorOf("wrench:\n  force_tolerance_share: 1.5\n"),
              HasSubstr("wrench.force_tolerance_share: 1.5 is out of range [0, 1)"));
  EXPECT_EQ(ParseParams("wrench:\n  force_tolerance_share: 0.1\n", Params{}).wrench.force_tolerance_share,
            0.1);
}

TEST(Params, PlanningWrenchAndPlacementSectionsAreStrict) {
  const Params p = ParseParams(
      "planning:\n  trajectories:\n    upward_distance: 0.3\n  cost:\n    max_displacement: 0.5\n"
      "wrench:\n  variant: joint_safe\n  rotation_angle: 1.0\nplacement:\n  yaw_only: false\n",
      ProfileParams("fast"));
  EXPECT_DOUBLE_EQ(p.planning.trajectories.upward_distance, 0.3);
  EXPECT_DOUBLE_EQ(p.planning.cost.max_displacement, 0.5);
  EXPECT_EQ(p.wrench.variant, ResolutionVariant::kJointSafe);
  EXPECT_DOUBLE_EQ(p.wrench.rotation_angle, 1.0);
  EXPECT_FALSE(p.placement.yaw_only);
  EXPECT_THAT(ErrorOf("planning:\n  grasps:\n    spacng: 0.01\n"), HasSubstr("planning.grasps.spacng"));
  EXPECT_THAT(ErrorOf("wrench:\n  variant: shake\n"), HasSubstr("wrench.variant"));
  EXPECT_THAT(ErrorOf("planning:\n  grasps:\n    spacing: 0\n"), HasSubstr("planning.grasps.spacing"));
  EXPECT_THAT(ErrorOf("planning:\n  cost:\n    height_weight: 0.9\n"), HasSubstr("weight"));
}

}  // namespace
}  // namespace tubepick
