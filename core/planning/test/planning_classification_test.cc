#include "core/planning/classification.h"

#include <limits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/planning/test/planning_test_util.h"

namespace tubepick {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using namespace testing_planning;  // NOLINT

TEST(Classification, CrossingTubesUpperNoneLowerWeak) {
  const ClassificationResult r = ClassifyTubes(CrossingTubes(), 0.0, ClassificationParams{});
  ASSERT_EQ(r.tubes.size(), 2u);
  ASSERT_EQ(r.classes.size(), 2u);
  EXPECT_EQ(r.tubes[0].occlusion, Occlusion::kNone);
  EXPECT_EQ(r.tubes[0].occluded_joint_count, 0u);
  EXPECT_TRUE(r.classes[0].occluded_joints.empty());
  EXPECT_EQ(r.tubes[1].occlusion, Occlusion::kWeak);
  EXPECT_EQ(r.tubes[1].occluded_joint_count, 1u);
  EXPECT_THAT(r.classes[1].occluded_joints, ElementsAre(0u));
  // Geometry and order untouched.
  EXPECT_EQ(r.tubes[1].cylinders[1].segment_id, 2u);
  EXPECT_EQ(r.tubes[0].id, 0u);
}

TEST(Classification, JointBetweenSameSegmentIsNotOccluded) {
  // Two cylinders fitted to one segment (a bend): the joint is not occluded.
  const Tube tube = MakeTube(0, {FlatCylinder(0, 0, 0.1, 0, 3), FlatCylinder(0.1, 0, 0.2, 0.05, 3),
                                 FlatCylinder(0.25, 0.05, 0.35, 0.05, 4)});
  EXPECT_THAT(OccludedJoints(tube), ElementsAre(1u));
  const ClassificationResult r = ClassifyTubes({tube}, 0.0, ClassificationParams{});
  EXPECT_EQ(r.tubes[0].occlusion, Occlusion::kWeak);
}

TEST(Classification, StrongWithTwoOccludedJoints) {
  const Tube tube = MakeTube(0, {FlatCylinder(-0.25, 0, -0.15, 0, 1), FlatCylinder(-0.11, 0, 0.05, 0, 2),
                                 FlatCylinder(0.09, 0, 0.25, 0, 3)});
  const ClassificationResult r = ClassifyTubes({tube}, 0.0, ClassificationParams{});
  EXPECT_EQ(r.tubes[0].occlusion, Occlusion::kStrong);
  EXPECT_EQ(r.tubes[0].occluded_joint_count, 2u);
  EXPECT_THAT(r.classes[0].occluded_joints, ElementsAre(0u, 1u));
}

TEST(Classification, OcclusionOfCounts) {
  EXPECT_EQ(OcclusionOf(0), Occlusion::kNone);
  EXPECT_EQ(OcclusionOf(1), Occlusion::kWeak);
  EXPECT_EQ(OcclusionOf(2), Occlusion::kStrong);
  EXPECT_EQ(OcclusionOf(5), Occlusion::kStrong);
}

TEST(Classification, SingleCylinderIsNonOccluded) {
  const ClassificationResult r = ClassifyTubes({MakeTube(0, {FlatCylinder(0, 0, 0.4, 0, 9)})}, 0.0, {});
  EXPECT_EQ(r.tubes[0].occlusion, Occlusion::kNone);
}

TEST(Classification, WeakSectionsSplitAtTheJoint) {
  const Tube tube = MakeTube(0, {FlatCylinder(0, 0, 0.1, 0, 1), FlatCylinder(0.1, 0, 0.2, 0, 1),
                                 FlatCylinder(0.24, 0, 0.3, 0, 2), FlatCylinder(0.3, 0, 0.4, 0, 2)});
  const auto [first, second] = SplitAtJoint(tube, 1);
  EXPECT_EQ(first, (CylinderRange{0, 2}));
  EXPECT_EQ(second, (CylinderRange{2, 4}));
  EXPECT_TRUE(first.contains(1));
  EXPECT_FALSE(first.contains(2));
  EXPECT_EQ(second.size(), 2u);
}

TEST(Classification, MinimumLengthFilter) {
  ClassificationParams params;
  params.length_tolerance = 0.15;  // expected 0.5 ⇒ minimum 0.35
  const std::vector<Tube> tubes = {MakeTube(0, {FlatCylinder(0, 0, 0.30, 0, 1)}),
                                   MakeTube(1, {FlatCylinder(0, 0.1, 0.36, 0.1, 2)})};
  EXPECT_DOUBLE_EQ(MinimumTubeLength(0.5, params), 0.35);
  const ClassificationResult r = ClassifyTubes(tubes, 0.5, params);
  EXPECT_TRUE(r.classes[0].too_short);
  EXPECT_FALSE(r.classes[1].too_short);
  // Still classified (it takes part in simulations as an obstacle).
  EXPECT_EQ(r.tubes[0].occlusion, Occlusion::kNone);
}

TEST(Classification, MinimumLengthSkippedWhenLengthUnknown) {
  const ClassificationResult r = ClassifyTubes({MakeTube(0, {FlatCylinder(0, 0, 0.05, 0, 1)})}, 0.0, {});
  EXPECT_FALSE(r.classes[0].too_short);
  EXPECT_EQ(MinimumTubeLength(0.0, ClassificationParams{}), 0.0);
  ClassificationParams wide;
  wide.length_tolerance = 1.0;
  EXPECT_EQ(MinimumTubeLength(0.5, wide), 0.0);
}

TEST(Classification, MinimumLengthCountsJoints) {
  // 0.15 + 0.04 (joint) + 0.17 = 0.36 ≥ 0.35.
  const Tube tube = MakeTube(0, {FlatCylinder(0, 0, 0.15, 0, 1), FlatCylinder(0.19, 0, 0.36, 0, 2)});
  EXPECT_FALSE(ClassifyTubes({tube}, 0.5, {}).classes[0].too_short);
}

TEST(Classification, RejectsEmptyTube) {
  try {
    ClassifyTubes({MakeTube(0, {FlatCylinder(0, 0, 0.3, 0, 1)}), MakeTube(1, {})}, 0.0, {});
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("tubes[1]"));
  }
}

TEST(Classification, RejectsNonFiniteCylinder) {
  Tube tube = MakeTube(0, {FlatCylinder(0, 0, 0.3, 0, 1)});
  tube.cylinders[0].end.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(ClassifyTubes({tube}, 0.0, {}), InvalidArgument);
}

TEST(Classification, RejectsNegativeTolerance) {
  ClassificationParams params;
  params.length_tolerance = -0.1;
  try {
    ClassifyTubes({}, 0.5, params);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("planning.classification.length_tolerance"));
  }
}

}  // namespace
}  // namespace tubepick
