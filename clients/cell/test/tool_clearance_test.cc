#include "clients/cell/tool_clearance.h"

#include <gtest/gtest.h>

namespace tubepick::cell {
namespace {

Eigen::Isometry3d Down(double x, double y, double z, double yaw = 0.0) {
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.linear() =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  X_BinTcp.translation() = Eigen::Vector3d(x, y, z);
  return X_BinTcp;
}

class ToolClearanceTest : public ::testing::Test {
 protected:
  CellConfig cell;  // bin 0.8 x 0.6 x 0.2 m
  ToolGeometry tool;
  const std::vector<Eigen::Vector3d> up{Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.4)};
};

TEST_F(ToolClearanceTest, CentreOfTheBinIsClear) {
  EXPECT_FALSE(ToolClearanceProblem(cell, tool, Down(0, 0, 0.02), 0.045, up));
}

TEST_F(ToolClearanceTest, HousingAcrossTheTubeHitsTheNearWall) {
  // Closing direction y_Tcp is ±y_Bin: the housing reaches 0.065 m each side; the wall is at 0.3 m,
  // the margin 3 mm: clear up to y = 0.232 m.
  EXPECT_FALSE(ToolClearanceProblem(cell, tool, Down(0, 0.23, 0.02), 0.045, up));
  const auto problem = ToolClearanceProblem(cell, tool, Down(0, 0.24, 0.02), 0.045, up);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("housing 0.008 m into the +y wall at waypoint 0"), std::string::npos) << *problem;
  // Turned by 90°, the housing's narrow side (0.03 m) faces the wall: clear.
  EXPECT_FALSE(ToolClearanceProblem(cell, tool, Down(0, 0.24, 0.02, M_PI / 2), 0.045, up));
}

TEST_F(ToolClearanceTest, EscapeTowardsTheWallIsCaughtAtItsWaypoint) {
  const std::vector<Eigen::Vector3d> escape{Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.02),
                                            Eigen::Vector3d(-0.2, 0, 0.02), Eigen::Vector3d(-0.2, 0, 0.42)};
  const auto problem = ToolClearanceProblem(cell, tool, Down(-0.2, 0, 0.02, M_PI / 2), 0.045, escape);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("-x wall at waypoint 2"), std::string::npos) << *problem;
}

TEST_F(ToolClearanceTest, GraspHighAboveTheWallsIsNotChecked) {
  // Everything of the tool at or above the wall top (0.2 m) is outside the walls' reach.
  EXPECT_FALSE(ToolClearanceProblem(cell, tool, Down(0, 0.35, 0.26), 0.045, up));
}

TEST_F(ToolClearanceTest, FingertipsBelowTheFloor) {
  const auto problem = ToolClearanceProblem(cell, tool, Down(0, 0, 0.004), 0.045, up);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("finger"), std::string::npos);
  EXPECT_NE(problem->find("below the floor"), std::string::npos);
}

}  // namespace
}  // namespace tubepick::cell
