#include "wire/proto_convert.h"

#include <gtest/gtest.h>

#include <cstring>

#include "core/common/errors.h"

namespace tubepick {
namespace {

TEST(ProtoConvertTest, PoseRoundTrips) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  EXPECT_TRUE(FromProto(ToProto(X), "pose").isApprox(X, 1e-12));
}

TEST(ProtoConvertTest, ZeroQuaternionIsRejectedNamingTheField) {
  v1::Pose pose;  // all zero
  try {
    FromProto(pose, "plans[2].place_tcp_pose");
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("plans[2].place_tcp_pose"), std::string::npos);
  }
}

TEST(ProtoConvertTest, CellDescriptionCarriesTheCaptureSensorPose) {
  CellConfig cell;
  Eigen::Isometry3d X_BinSensor = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.1, 1.2));
  const v1::CellDescription d = ToCellDescription(cell, X_BinSensor);
  EXPECT_DOUBLE_EQ(d.sensor_pose().position().z(), 1.2);
  EXPECT_DOUBLE_EQ(d.tube_radius(), cell.tube.radius);
  EXPECT_DOUBLE_EQ(d.bin_inner_size().x(), cell.bin.inner_size.x());
  EXPECT_DOUBLE_EQ(d.place_pose().position().y(), cell.place.X_BinPlace.translation().y());
  // The junction layout of branched parts goes along (0 = unknown).
  EXPECT_EQ(d.tube_junctions(), 0u);
  cell.tube.layout = JunctionLayout{2, 0.30, 0.15};
  const v1::CellDescription trees = ToCellDescription(cell, X_BinSensor);
  EXPECT_EQ(trees.tube_junctions(), 2u);
  EXPECT_DOUBLE_EQ(trees.tube_junction_spacing(), 0.30);
  EXPECT_DOUBLE_EQ(trees.tube_branch_length(), 0.15);
}

}  // namespace
}  // namespace tubepick

namespace tubepick {
namespace {

Cylinder TestCylinder(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Cylinder c;
  c.start = a;
  c.end = b;
  c.radius = 0.0125;
  return c;
}

TEST(ProtoConvertTest, ALinearTubeGoesOutAsOneBranchBetweenTwoEnds) {
  Tube t;
  t.id = 4;
  t.cylinders = {TestCylinder({0, 0, 0}, {0.1, 0, 0}), TestCylinder({0.12, 0, 0}, {0.2, 0, 0})};
  const v1::Tube out = ToProto(t);
  ASSERT_EQ(out.branches_size(), 1);
  EXPECT_EQ(out.branches(0).from_node(), 0u);
  EXPECT_EQ(out.branches(0).to_node(), 1u);
  EXPECT_EQ(out.branches(0).first_cylinder(), 0u);
  EXPECT_EQ(out.branches(0).cylinder_count(), 2u);
  ASSERT_EQ(out.nodes_size(), 2);
  EXPECT_DOUBLE_EQ(out.nodes(1).position().x(), 0.2);
  EXPECT_NEAR(out.length(), 0.2, 1e-12);
}

TEST(ProtoConvertTest, ABranchedTubeCarriesItsNodesAndBranches) {
  Tube t;
  t.cylinders = {TestCylinder({0, 0, 0}, {0.1, 0, 0}), TestCylinder({0.1, 0, 0}, {0.2, 0, 0}),
                 TestCylinder({0.1, 0.03, 0}, {0.1, 0.13, 0})};
  t.nodes = {TubeNode{{0, 0, 0}}, TubeNode{{0.1, 0, 0}}, TubeNode{{0.2, 0, 0}}, TubeNode{{0.1, 0.13, 0}}};
  t.branches = {TubeBranch{0, 1, 0, 1}, TubeBranch{1, 2, 1, 1}, TubeBranch{1, 3, 2, 1}};
  const v1::Tube out = ToProto(t);
  ASSERT_EQ(out.nodes_size(), 4);
  ASSERT_EQ(out.branches_size(), 3);
  EXPECT_EQ(out.branches(2).from_node(), 1u);
  EXPECT_EQ(out.branches(2).to_node(), 3u);
  EXPECT_EQ(out.branches(2).first_cylinder(), 2u);
  EXPECT_EQ(out.branches(2).cylinder_count(), 1u);
  EXPECT_DOUBLE_EQ(out.nodes(3).position().y(), 0.13);
  EXPECT_NEAR(out.length(), 0.2 + 0.03 + 0.1, 1e-12);  // the junction link counts
}

}  // namespace
}  // namespace tubepick
