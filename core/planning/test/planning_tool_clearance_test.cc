// The tool-clearance grasp filter (core/planning/tool_clearance.h) and its place in PlanPick.

#include "core/planning/tool_clearance.h"

#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/params.h"
#include "core/planning/grasp_synthesis.h"
#include "core/planning/pick_planner.h"
#include "core/planning/test/planning_test_util.h"
#include "core/planning/trajectory_synthesis.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
using namespace testing_planning;  // NOLINT

const std::vector<Eigen::Vector3d> kUp{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, 0.4)};

// The grasp frame of a tube along x_Bin at (x, y, z): y_Tcp (closing) along ±y_Bin.
Eigen::Isometry3d AcrossX(double x, double y, double z) {
  return *GraspFrame(Eigen::Vector3d(x, y, z), Eigen::Vector3d::UnitX());
}

ModelingResult Model(std::vector<Tube> tubes) {
  ModelingResult m;
  m.tubes = std::move(tubes);
  m.max_height = 0.05;
  return m;
}

// Default bin 0.8 × 0.6 × 0.2 m (walls at x = ±0.4, y = ±0.3), default tool (2F-85 as simulated).
TEST(ToolClearance, HousingAcrossATubeNearALongWall) {
  const BinConfig bin;
  const ToolParams tool;
  // Closing across y: the housing reaches 0.065 m each side, 0.065 m above the TCP, below the wall
  // top for a tube on the floor; with the 3 mm margin it clears up to |y| = 0.3 − 0.068 = 0.232.
  EXPECT_TRUE(ToolClears(bin, tool, AcrossX(0.0, 0.230, kR), 0.045, kUp));
  const auto issue = ToolClearanceProblem(bin, tool, AcrossX(0.0, -0.240, kR), 0.045, kUp);
  ASSERT_TRUE(issue);
  EXPECT_EQ(issue->part, "housing");
  EXPECT_EQ(issue->surface, "-y");
  EXPECT_NEAR(issue->depth, 0.008, 1e-9);
  EXPECT_EQ(issue->waypoint, 0u);
  EXPECT_THAT(issue->ToString(), HasSubstr("housing 0.008 m into the -y wall at waypoint 0"));
  // The same grasp on a tube lying 0.14 m up: the housing's bottom (0.205 m) is above the wall top,
  // only the pads (outer faces 0.0325 m from the axis) count: clear.
  EXPECT_TRUE(ToolClears(bin, tool, AcrossX(0.0, -0.240, 0.14), 0.045, kUp));
  // ... until the pads reach the wall: 0.3 − 0.0325 − 0.003 = 0.2645.
  const auto pad = ToolClearanceProblem(bin, tool, AcrossX(0.0, -0.27, 0.14), 0.045, kUp);
  ASSERT_TRUE(pad);
  EXPECT_EQ(pad->part, "finger");
  EXPECT_NEAR(pad->depth, 0.0055, 1e-9);
}

TEST(ToolClearance, FingertipsBelowTheFloor) {
  // Fingertips 5 mm below the TCP: a TCP at 6 mm leaves 1 mm, less than the 3 mm margin.
  const auto issue = ToolClearanceProblem(BinConfig{}, ToolParams{}, AcrossX(0.0, 0.0, 0.006), 0.045, kUp);
  ASSERT_TRUE(issue);
  EXPECT_EQ(issue->surface, "floor");
  EXPECT_NEAR(issue->depth, 0.002, 1e-9);
  EXPECT_TRUE(ToolClears(BinConfig{}, ToolParams{}, AcrossX(0.0, 0.0, 0.009), 0.045, kUp));
}

TEST(ToolClearance, EscapeWaypointSwingsTheHousingIntoAWall) {
  // A tube along y at x = 0.25 (closing along x): clear at the grasp and straight up (housing
  // 0.065 m + margin ⇒ x ≤ 0.332), but the escape's lateral move of 0.1 m towards +x puts the
  // housing 0.018 m into the +x wall at its third waypoint (2 cm up, still below the wall top).
  const Eigen::Isometry3d X = *GraspFrame(Eigen::Vector3d(0.25, 0.0, kR), Eigen::Vector3d::UnitY());
  EXPECT_TRUE(ToolClears(BinConfig{}, ToolParams{}, X, 0.045, kUp));
  const std::vector<Eigen::Vector3d> escape{Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.02),
                                            Eigen::Vector3d(0.1, 0, 0.02), Eigen::Vector3d(0.1, 0, 0.42)};
  const auto issue = ToolClearanceProblem(BinConfig{}, ToolParams{}, X, 0.045, escape);
  ASSERT_TRUE(issue);
  EXPECT_EQ(issue->part, "housing");
  EXPECT_EQ(issue->surface, "+x");
  EXPECT_EQ(issue->waypoint, 2u);
  EXPECT_NEAR(issue->depth, 0.018, 1e-9);
}

TEST(ToolClearance, PlannerRejectsEveryGraspOfATubeAlongAWall) {
  // A 0.4 m tube along the −y wall, its axis 0.05 m from the wall: 19 grasps, all rejected.
  const ModelingResult wall = Model({MakeTube(0, {FlatCylinder(-0.2, -0.25, 0.2, -0.25, 1)})});
  const PickPlanResult r = PlanPick(wall, CellConfig{}, PlanningParams{}, nullptr, 1);
  EXPECT_TRUE(r.plans.empty());
  EXPECT_FALSE(r.bin_empty);
  EXPECT_EQ(r.counts.grasp_candidates, 19u);
  EXPECT_EQ(r.counts.rejected_tool, 19u);
  EXPECT_EQ(r.planned_class, Occlusion::kUnspecified);

  // The same tube in the middle of the bin keeps all 19.
  const ModelingResult centre = Model({MakeTube(0, {FlatCylinder(-0.2, 0.0, 0.2, 0.0, 1)})});
  const PickPlanResult c = PlanPick(centre, CellConfig{}, PlanningParams{}, nullptr, 1);
  EXPECT_EQ(c.plans.size(), 19u);
  EXPECT_EQ(c.counts.rejected_tool, 0u);

  // With the check off the wall tube's grasps are back (the controller would have to skip them).
  PlanningParams off;
  off.tool.check = false;
  EXPECT_EQ(PlanPick(wall, CellConfig{}, off, nullptr, 1).plans.size(), 19u);
}

TEST(ToolClearance, PlannerFallsThroughToAnOccludedTube) {
  // Tube 0 lies on top along x, 0.05 m from the −y wall (non-occluded, no executable grasp for a
  // vertical tool); tube 1 runs along y under it (split at the crossing: weakly occluded) into the
  // middle.
  const std::vector<Tube> tubes = {
      MakeTube(0, {FlatCylinder(-0.2, -0.25, 0.2, -0.25, 7, 3.0 * kR)}),
      MakeTube(1, {FlatCylinder(0.0, -0.29, 0.0, -0.27, 1), FlatCylinder(0.0, -0.23, 0.0, 0.15, 2)})};
  PlanningParams vertical;
  vertical.grasps.max_tilt = 0.0;
  const PickPlanResult r = PlanPick(Model(tubes), CellConfig{}, vertical, nullptr, 1);
  ASSERT_EQ(r.classes.size(), 2u);
  EXPECT_EQ(r.tubes[0].occlusion, Occlusion::kNone);
  EXPECT_EQ(r.tubes[1].occlusion, Occlusion::kWeak);
  EXPECT_EQ(r.planned_class, Occlusion::kWeak);
  ASSERT_FALSE(r.plans.empty());
  for (const PickPlan& p : r.plans) {
    EXPECT_EQ(p.tube_id, 1u);
    EXPECT_TRUE(
        ToolClears(CellConfig{}.bin, ToolParams{}, p.grasp.X_BinTcp, p.grasp.opening_width, p.waypoints));
  }
  EXPECT_GE(r.counts.rejected_tool, 19u);  // every grasp of tube 0

  // Without the check the planner stops at tube 0 (stage 1), whose grasps the tool cannot execute.
  PlanningParams off = vertical;
  off.tool.check = false;
  const PickPlanResult o = PlanPick(Model(tubes), CellConfig{}, off, nullptr, 1);
  EXPECT_EQ(o.planned_class, Occlusion::kNone);
  ASSERT_FALSE(o.plans.empty());
  EXPECT_EQ(o.plans.front().tube_id, 0u);

  // With tilted grasps (the default) tube 0 is grasped after all, first: 5 cm from the wall the
  // housing clears when the tool turns 15° (its near bottom corner 4.6 cm from the axis).
  const PickPlanResult t = PlanPick(Model(tubes), CellConfig{}, PlanningParams{}, nullptr, 1);
  EXPECT_EQ(t.planned_class, Occlusion::kNone);
  ASSERT_FALSE(t.plans.empty());
  EXPECT_EQ(t.plans.front().tube_id, 0u);
  EXPECT_NEAR(std::abs(t.plans.front().grasp.tilt), M_PI / 12, 1e-12);
}

TEST(ToolClearance, TiltsTurnTheToolAboutTheTubeBothWaysSmallestFirst) {
  GraspParams params;  // 15° steps up to 30°
  EXPECT_THAT(GraspTilts(params), ::testing::ElementsAre(::testing::DoubleNear(M_PI / 12, 1e-12),
                                                         ::testing::DoubleNear(-M_PI / 12, 1e-12),
                                                         ::testing::DoubleNear(M_PI / 6, 1e-12),
                                                         ::testing::DoubleNear(-M_PI / 6, 1e-12)));
  params.max_tilt = 0.0;
  EXPECT_TRUE(GraspTilts(params).empty());

  Grasp vertical;
  vertical.X_BinTcp = AcrossX(0.1, 0.2, 0.05);
  vertical.p_Bin_grasp = vertical.X_BinTcp.translation();
  const Grasp tilted = TiltedGrasp(vertical, 0.3);
  EXPECT_DOUBLE_EQ(tilted.tilt, 0.3);
  EXPECT_TRUE(tilted.X_BinTcp.translation().isApprox(vertical.X_BinTcp.translation()));
  EXPECT_TRUE(tilted.X_BinTcp.linear().col(0).isApprox(Eigen::Vector3d::UnitX()));  // across the tube still
  EXPECT_TRUE(tilted.approach_Bin.isApprox(tilted.X_BinTcp.linear().col(2)));
  EXPECT_NEAR(tilted.approach_Bin.z(), -std::cos(0.3), 1e-12);
  EXPECT_NEAR(std::abs(tilted.approach_Bin.y()), std::sin(0.3), 1e-12);
}

TEST(ToolClearance, ATubeAlongAWallIsGraspedWithTheToolTiltedAwayFromIt) {
  // Seed 12's last tree (2026-12-05): along the +y wall, its axis 3.9 cm from the wall, 5.6 cm up.
  // A vertical tool's housing (0.068 m from the axis with the margin) would be 2.9 cm into the
  // wall; turned 15° still 1.0 cm; turned 30° it clears, and the lower pad stays 3.5 cm above
  // the floor.
  const ModelingResult wall = Model({MakeTube(0, {FlatCylinder(-0.2, 0.261, 0.2, 0.261, 1, 0.056)})});
  PlanningParams vertical;
  vertical.grasps.max_tilt = 0.0;
  const PickPlanResult v = PlanPick(wall, CellConfig{}, vertical, nullptr, 1);
  EXPECT_TRUE(v.plans.empty());
  EXPECT_EQ(v.counts.rejected_tool, 19u);

  const PickPlanResult r = PlanPick(wall, CellConfig{}, PlanningParams{}, nullptr, 1);
  ASSERT_EQ(r.plans.size(), 19u);
  EXPECT_EQ(r.counts.rejected_tool, 0u);
  EXPECT_EQ(r.counts.tilted_grasps, 19u);
  for (const PickPlan& p : r.plans) {
    EXPECT_NEAR(std::abs(p.grasp.tilt), M_PI / 6, 1e-12);
    // The approach runs down towards the wall: the tool's top leans away from it.
    EXPECT_NEAR(p.grasp.approach_Bin.y(), 0.5, 1e-9);
    EXPECT_TRUE(p.grasp.approach_Bin.isApprox(p.grasp.X_BinTcp.linear().col(2)));
    EXPECT_TRUE(
        ToolClears(CellConfig{}.bin, ToolParams{}, p.grasp.X_BinTcp, p.grasp.opening_width, p.waypoints));
  }

  // On the floor the same tube keeps no grasp: turned, the lower pad would dig into the floor.
  const ModelingResult low = Model({MakeTube(0, {FlatCylinder(-0.2, 0.261, 0.2, 0.261, 1)})});
  const PickPlanResult f = PlanPick(low, CellConfig{}, PlanningParams{}, nullptr, 1);
  EXPECT_TRUE(f.plans.empty());
  EXPECT_EQ(f.counts.rejected_tool, 19u);
}

TEST(ToolClearance, ParamsSectionReadsWritesAndValidates) {
  const Params base = ProfileParams("fast");
  EXPECT_NE(DumpParams(base).find("tool:"), std::string::npos);
  const Params p = ParseParams(
      "planning:\n  tool:\n    check: false\n    housing_size: [0.05, 0.12, 0.1]\n"
      "    margin: 0.005\n",
      base);
  EXPECT_FALSE(p.planning.tool.check);
  EXPECT_DOUBLE_EQ(p.planning.tool.housing_size.y(), 0.12);
  EXPECT_DOUBLE_EQ(p.planning.tool.margin, 0.005);
  EXPECT_DOUBLE_EQ(p.planning.tool.finger_size.x(), 0.022);  // untouched: the default
  const Params again = ParseParams(DumpParams(p), base);
  EXPECT_DOUBLE_EQ(again.planning.tool.housing_size.z(), 0.1);
  EXPECT_FALSE(again.planning.tool.check);
  try {
    ParseParams("planning:\n  tool:\n    margin: -0.001\n", base);
    FAIL() << "negative margin accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("planning.tool.margin"));
  }
  try {
    ParseParams("planning:\n  grasps:\n    max_tilt: 1.2\n", base);
    FAIL() << "a tilt beyond 60 degrees accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("planning.grasps.max_tilt"));
    EXPECT_THAT(e.what(), HasSubstr("1.2"));
  }
  try {  // 40°: within the grasps' range, beyond what AnalyzeWrench accepts (35°)
    ParseParams("planning:\n  grasps:\n    max_tilt: 0.7\n", base);
    FAIL() << "a grasp tilt beyond wrench.max_tilt accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("planning.grasps.max_tilt: 0.7"));
    EXPECT_THAT(e.what(), HasSubstr("wrench.max_tilt 0.61"));
  }
  try {
    ParseParams("planning:\n  tool:\n    pad_size: 0.01\n", base);
    FAIL() << "unknown key accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("planning.tool.pad_size"));
  }
}

}  // namespace
}  // namespace tubepick
