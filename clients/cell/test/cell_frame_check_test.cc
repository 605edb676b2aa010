#include "clients/cell/cell_frame_check.h"

#include <gtest/gtest.h>

#include "clients/cell/test/scripted_cell.h"
#include "core/common/errors.h"
#include "core/placement/placement.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

using testing::DownPose;

/// A plan as the planner makes it: a tube lying along x through `p_Bin_centre`, grasped at
/// `p_Bin_grasp` (TCP down, turned `yaw` about the vertical), lifted 0.4 m, and its place pose for
/// the planner's place frame `X_BinPlacePlanner` (core's placement, yaw-only, centroid origin).
struct PlannerPlan {
  v1::Tube tube;
  PlanFrameInput input;

  PlannerPlan(const Eigen::Isometry3d& X_BinPlacePlanner, const PlacementParams& placement = {},
              double yaw = 0.3) {
    const Eigen::Vector3d p_Bin_start(-0.15, -0.05, 0.0125), p_Bin_end(0.25, 0.05, 0.0125);
    tube.set_id(3);
    v1::Cylinder* c = tube.add_cylinders();
    *c->mutable_start() = ToProto(p_Bin_start);
    *c->mutable_end() = ToProto(p_Bin_end);
    c->set_radius(0.0125);
    Eigen::Isometry3d X_BinTcpGrasp = DownPose(p_Bin_start + 0.7 * (p_Bin_end - p_Bin_start));
    X_BinTcpGrasp.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * X_BinTcpGrasp.linear();
    Tube model;
    model.cylinders.push_back({p_Bin_start, p_Bin_end, 0.0125});
    const std::optional<TubeFrame> frame = EstimateTubeFrame(model, placement, X_BinTcpGrasp.translation());
    input.X_BinTcpGrasp = X_BinTcpGrasp;
    input.X_BinTcpPreGrasp = X_BinTcpGrasp;
    input.X_BinTcpPreGrasp.translation().z() += 0.1;
    input.waypoints_Bin = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.4)};
    input.X_BinTcpPlace = PlanPlacement(X_BinTcpGrasp, *frame, X_BinPlacePlanner, placement).X_BinTcpPlace;
    input.tube = &tube;
  }
  PlannerPlan(const PlannerPlan&) = delete;
};

std::string Problem(const CellConfig& cell, const PlanFrameInput& input, CellFrameCheckParams params = {}) {
  return CellFrameProblem(cell, params, input).value_or("");
}

TEST(CellFrameCheckTest, APlanOfThisCellFits) {
  const CellConfig cell;
  const PlannerPlan plan(cell.place.X_BinPlace);
  EXPECT_EQ(Problem(cell, plan.input), "");
  // The planner's other placement options give the same place frame.
  PlacementParams grasp_origin;
  grasp_origin.origin = TubeFrameOrigin::kGraspPoint;
  grasp_origin.sign = AxisSign::kAwayFromGrasp;
  const PlannerPlan other(cell.place.X_BinPlace, grasp_origin);
  EXPECT_EQ(Problem(cell, other.input), "");
  // So does a place frame turned a half turn about z (a tube is symmetric end to end).
  CellConfig turned = cell;
  turned.place.X_BinPlace.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_EQ(Problem(turned, plan.input), "");
}

TEST(CellFrameCheckTest, APlaceFrameElsewhereIsNamedWithTheDistance) {
  const CellConfig cell;
  Eigen::Isometry3d X_BinPlacePlanner = cell.place.X_BinPlace;
  X_BinPlacePlanner.translation() += Eigen::Vector3d(0.0, 0.2, 0.0);  // 20 cm off
  const PlannerPlan plan(X_BinPlacePlanner);
  const std::string problem = Problem(cell, plan.input);
  EXPECT_NE(
      problem.find("lays the tube with its frame at (0.000, 1.000, 0.100) m at best, 0.200 m from this "
                   "controller's place frame at (0.000, 0.800, 0.100) m (place_position_tolerance 0.050 m)"),
      std::string::npos)
      << problem;
  EXPECT_NE(problem.find("another place frame (cell place.pose_in_bin)"), std::string::npos) << problem;
  // Within the tolerance it fits.
  CellFrameCheckParams loose;
  loose.place_position_tolerance = 0.25;
  EXPECT_EQ(Problem(cell, plan.input, loose), "");
}

TEST(CellFrameCheckTest, APlaceFrameTurnedAboutTheVerticalIsNamedWithTheAngle) {
  const CellConfig cell;
  Eigen::Isometry3d X_BinPlacePlanner = cell.place.X_BinPlace;
  X_BinPlacePlanner.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const PlannerPlan plan(X_BinPlacePlanner);
  const std::string problem = Problem(cell, plan.input);
  EXPECT_NE(problem.find("lays the tube turned 90.0 deg from this controller's place frame"),
            std::string::npos)
      << problem;
}

TEST(CellFrameCheckTest, APlaceFrameTiltedIsSeenWithoutATubeModel) {
  const CellConfig cell;
  Eigen::Isometry3d X_BinPlacePlanner = cell.place.X_BinPlace;
  X_BinPlacePlanner.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()).toRotationMatrix();
  PlannerPlan plan(X_BinPlacePlanner);
  plan.input.tube = nullptr;  // the answer did not carry the tube's model
  const std::string problem = Problem(cell, plan.input);
  EXPECT_NE(problem.find("tilts the tube 28.6 deg against the z axis of this controller's place frame"),
            std::string::npos)
      << problem;
  // Without a model, a place TCP within the tube's length of the place frame is all that can be said.
  const PlannerPlan fits(cell.place.X_BinPlace);
  PlanFrameInput unmodeled = fits.input;
  unmodeled.tube = nullptr;
  EXPECT_EQ(Problem(cell, unmodeled), "");
}

TEST(CellFrameCheckTest, PosesOutsideTheBinAreNamedWithTheBoundAndTheLikelyCause) {
  const CellConfig cell;  // 0.8 x 0.6 x 0.2 m
  PlanFrameInput input;
  input.X_BinTcpGrasp = DownPose(Eigen::Vector3d(0.0, 0.33, 0.03));
  input.X_BinTcpPreGrasp = DownPose(Eigen::Vector3d(0.0, 0.33, 0.13));
  std::string problem = Problem(cell, input);
  EXPECT_NE(
      problem.find("cell check: the grasp at (0.000, 0.330, 0.030) m lies outside this controller's bin "
                   "(inner 0.800 x 0.600 x 0.200 m, bin_margin 0.020 m: |y| > 0.320 m); the planner is "
                   "likely configured with another bin (cell bin.inner_size) or sensor pose"),
      std::string::npos)
      << problem;
  // Above the wall top: misconfigured, or a tube leaning on a wall (the operator's matter).
  input.X_BinTcpGrasp = DownPose(Eigen::Vector3d(-0.333, -0.207, 0.317));
  input.X_BinTcpPreGrasp = DownPose(Eigen::Vector3d(-0.333, -0.207, 0.417));
  problem = Problem(cell, input);
  EXPECT_NE(
      problem.find("z > 0.220 m, 0.117 m above the wall top (cell_check.grasp_above_walls 0.000 m)); the "
                   "planner is likely configured with another bin"),
      std::string::npos)
      << problem;
  EXPECT_NE(problem.find("or a tube lies that high: leaning on a wall, partly outside the bin"),
            std::string::npos)
      << problem;
  // A cell whose heap rises above the walls allows it, up to the bound and the margin.
  CellFrameCheckParams heap;
  heap.grasp_above_walls = 0.3;
  EXPECT_EQ(Problem(cell, input, heap), "");
  input.X_BinTcpGrasp = DownPose(Eigen::Vector3d(0.0, 0.0, 0.53));
  input.X_BinTcpPreGrasp = DownPose(Eigen::Vector3d(0.0, 0.0, 0.63));
  problem = Problem(cell, input, heap);
  EXPECT_NE(problem.find("z > 0.520 m, 0.330 m above the wall top (cell_check.grasp_above_walls 0.300 m)"),
            std::string::npos)
      << problem;
  input.X_BinTcpGrasp = DownPose(Eigen::Vector3d(0.0, 0.0, 0.03));
  input.X_BinTcpPreGrasp = DownPose(Eigen::Vector3d(0.0, 0.0, 0.13));
  input.waypoints_Bin = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0.2, 0, 0.02),
                         Eigen::Vector3d(0.5, 0, 0.4)};
  problem = Problem(cell, input);
  EXPECT_NE(problem.find("the lift waypoint 2 at (0.500, 0.000, 0.430) m lies outside"), std::string::npos)
      << problem;
  // Lifted above the wall top is fine; millimetres are named as such.
  input.waypoints_Bin = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.4)};
  EXPECT_EQ(Problem(cell, input), "");
  input.X_BinTcpGrasp = DownPose(Eigen::Vector3d(12.0, -4.0, 30.0));
  EXPECT_NE(Problem(cell, input).find("millimetres read as metres"), std::string::npos);
  // The check can be turned off.
  CellFrameCheckParams off;
  off.enabled = false;
  EXPECT_EQ(Problem(cell, input, off), "");
}

TEST(CellFrameCheckTest, BadParamsNameTheField) {
  CellFrameCheckParams params;
  params.bin_margin = -0.1;
  EXPECT_THROW(params.Validate(), InvalidArgument);
  params = {};
  params.grasp_above_walls = -0.3;
  EXPECT_THROW(params.Validate(), InvalidArgument);
  params = {};
  params.place_rotation_tolerance = 30.0;
  try {
    params.Validate();
    FAIL() << "30 rad accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("cell_check.place_rotation_tolerance"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace tubepick::cell
