#include "clients/cell/wire_convert.h"

#include <gtest/gtest.h>

#include <cstring>

#include "core/common/errors.h"

namespace tubepick::cell {
namespace {

TEST(WireConvertTest, CloudIsPackedLittleEndianFloat32) {
  const Points points = {Eigen::Vector3f(1.0f, -2.0f, 0.5f)};
  const std::string xyz = PackCloudXyz(points);
  ASSERT_EQ(xyz.size(), 12u);
  // 1.0f = 0x3F800000, little-endian: 00 00 80 3F.
  EXPECT_EQ(static_cast<unsigned char>(xyz[0]), 0x00);
  EXPECT_EQ(static_cast<unsigned char>(xyz[2]), 0x80);
  EXPECT_EQ(static_cast<unsigned char>(xyz[3]), 0x3F);
  // -2.0f = 0xC0000000.
  EXPECT_EQ(static_cast<unsigned char>(xyz[7]), 0xC0);
  float z = 0.0f;
  std::memcpy(&z, xyz.data() + 8, 4);  // this machine is little-endian too
  EXPECT_EQ(z, 0.5f);
}

TEST(WireConvertTest, PoseRoundTrips) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  EXPECT_TRUE(FromWire(ToWire(X), "pose").isApprox(X, 1e-12));
}

TEST(WireConvertTest, ZeroQuaternionIsRejectedNamingTheField) {
  v1::Pose pose;  // all zero
  try {
    FromWire(pose, "plans[2].place_tcp_pose");
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("plans[2].place_tcp_pose"), std::string::npos);
  }
}

TEST(WireConvertTest, CellDescriptionCarriesTheCaptureSensorPose) {
  CellConfig cell;
  Eigen::Isometry3d X_BinSensor = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.1, 1.2));
  const v1::CellDescription d = ToCellDescription(cell, X_BinSensor);
  EXPECT_DOUBLE_EQ(d.sensor_pose().position().z(), 1.2);
  EXPECT_DOUBLE_EQ(d.tube_radius(), cell.tube.radius);
  EXPECT_DOUBLE_EQ(d.bin_inner_size().x(), cell.bin.inner_size.x());
  EXPECT_DOUBLE_EQ(d.place_pose().position().y(), cell.place.X_BinPlace.translation().y());
}

}  // namespace
}  // namespace tubepick::cell
