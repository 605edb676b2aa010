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
}

}  // namespace
}  // namespace tubepick
