#include "core/planning/classification.h"

#include <limits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/common/tube_graph.h"
#include "core/planning/grasp_filters.h"
#include "core/planning/grasp_ranking.h"
#include "core/planning/test/planning_test_util.h"
#include "core/planning/trajectory_synthesis.h"

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

namespace tubepick {
namespace {

using testing_planning::MakeCylinder;

// A tee: a run along x cut at x = 0.10, and a branch along y starting `link` from the node.
Tube Tee(double link) {
  Tube t;
  t.cylinders = {MakeCylinder({0, 0, 0.0125}, {0.10, 0, 0.0125}, 0),
                 MakeCylinder({0.10, 0, 0.0125}, {0.20, 0, 0.0125}, 0),
                 MakeCylinder({0.10, link, 0.0125}, {0.10, link + 0.10, 0.0125}, 1)};
  t.nodes = {TubeNode{{0, 0, 0.0125}}, TubeNode{{0.10, 0, 0.0125}}, TubeNode{{0.20, 0, 0.0125}},
             TubeNode{{0.10, link + 0.10, 0.0125}}};
  t.branches = {TubeBranch{0, 1, 0, 1}, TubeBranch{1, 2, 1, 1}, TubeBranch{1, 3, 2, 1}};
  return t;
}

TEST(ClassificationOfBranchedTubes, AJunctionLinkIsOccludedOnlyWhenLongerThanARadiusPlusTheGap) {
  ClassificationParams params;  // junction_gap 0.02: links up to 0.0325 m are a junction seen whole
  EXPECT_TRUE(OccludedJoints(Tee(0.03), params).empty());
  EXPECT_EQ(OccludedJoints(Tee(0.05), params), (std::vector<std::uint32_t>{0}));
  params.junction_gap = 0.05;
  EXPECT_TRUE(OccludedJoints(Tee(0.05), params).empty());
  const ClassificationResult result = ClassifyTubes({Tee(0.05)}, 0.0, ClassificationParams{});
  EXPECT_EQ(result.classes[0].occlusion, Occlusion::kWeak);
}

TEST(ClassificationOfBranchedTubes, AWeaklyOccludedTreeEscapesAlongItsOccludedJoint) {
  // The tee's one occluded joint is the 5 cm link from the node (0.10, 0) to the branch along +y.
  const Tube tee = Tee(0.05);
  const ClassificationResult result = ClassifyTubes({tee}, 0.0, ClassificationParams{});
  ASSERT_EQ(result.classes[0].occlusion, Occlusion::kWeak);
  SafetyZone zone;
  zone.min = Eigen::Vector2d(-0.4, -0.3);
  zone.max = Eigen::Vector2d(0.4, 0.3);
  const std::vector<Trajectory> trajectories =
      SynthesizeTrajectories(0, result.tubes[0], result.classes[0], 0.0125, zone, TrajectoryParams{});
  ASSERT_EQ(trajectories.size(), 3u);
  EXPECT_EQ(trajectories[0].kind, TrajectoryKind::kUpward);
  EXPECT_TRUE(trajectories[0].section_mask.empty());
  // Towards the branch (+y): the run trails under the occluder, the branch is held; the run lies
  // on the escape line (d_var 0), so the move is d_const = 3 r.
  const Trajectory& towards_branch = trajectories[1];
  EXPECT_EQ(towards_branch.kind, TrajectoryKind::kEscape);
  EXPECT_TRUE(towards_branch.escape_direction.isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_EQ(towards_branch.section_mask, (std::vector<std::uint8_t>{0, 0, 1}));
  EXPECT_NEAR(towards_branch.waypoints[2].y(), 3.0 * 0.0125, 1e-12);
  // Towards the run (−y): the 10 cm branch trails from 5 cm off the node: d_var 0.10 + 3 r.
  const Trajectory& towards_run = trajectories[2];
  EXPECT_TRUE(towards_run.escape_direction.isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_EQ(towards_run.section_mask, (std::vector<std::uint8_t>{1, 1, 0}));
  EXPECT_NEAR(towards_run.waypoints[2].y(), -(0.10 + 3.0 * 0.0125), 1e-12);
  // The grasp filter follows the mask.
  Grasp on_branch, on_run;
  on_branch.cylinder_index = 2;
  on_run.cylinder_index = 1;
  EXPECT_TRUE(InAllowedSection(on_branch, towards_branch));
  EXPECT_FALSE(InAllowedSection(on_run, towards_branch));
  EXPECT_TRUE(InAllowedSection(on_run, towards_run));

  // A strongly occluded tree is still lifted straight up only.
  TubeClass strong = result.classes[0];
  strong.occlusion = Occlusion::kStrong;
  strong.occluded_joints = {0, 0};
  EXPECT_EQ(SynthesizeTrajectories(0, result.tubes[0], strong, 0.0125, zone, TrajectoryParams{}).size(), 1u);
}

TEST(ClassificationOfBranchedTubes, TheSidesOfAJointAreTheTwoSubtrees) {
  // The run's first cylinder stops 2 cm short of the node: joint 0 links it to the node; joint 1
  // is the branch's link.
  Tube tee = Tee(0.05);
  tee.cylinders[0].end.x() = 0.08;
  ASSERT_EQ(TubeJoints(tee).size(), 2u);
  EXPECT_EQ(SideOfJointA(tee, 0), (std::vector<std::uint8_t>{1, 0, 0}));
  EXPECT_EQ(SideOfJointA(tee, 1), (std::vector<std::uint8_t>{1, 1, 0}));
}

TEST(ClassificationOfBranchedTubes, GraspsNearTheWholeTubesMassCentreCostLess) {
  const Tube tee = Tee(0.03);
  const Eigen::Vector3d centre = TubeMassCentre(tee);
  Grasp near, far;
  near.p_Bin_grasp = Eigen::Vector3d(0.10, 0.0, 0.0125);  // on the run, under the branch
  far.p_Bin_grasp = Eigen::Vector3d(0.01, 0.0, 0.0125);   // at the run's end
  EXPECT_LT(GraspCentreCost(near, tee), 0.3);
  EXPECT_GT(GraspCentreCost(far, tee), 0.6);
  EXPECT_NEAR(GraspCentreCost(near, tee), MassCentreCost(near.p_Bin_grasp, tee), 0.0);
  EXPECT_NEAR(MassCentreCost(centre, tee), 0.0, 1e-12);
  // A linear tube keeps the along-curve cost of the thesis.
  Tube run;
  run.cylinders = {tee.cylinders[0], tee.cylinders[1]};
  Grasp middle;
  middle.curve_position = 0.10;
  EXPECT_NEAR(GraspCentreCost(middle, run), 0.0, 1e-12);
}

}  // namespace
}  // namespace tubepick
