#include "wire/packed_cloud.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>

namespace tubepick {
namespace {

TEST(PackedCloud, IsLittleEndianFloat32) {
  const Points points = {Eigen::Vector3f(1.0f, -2.0f, 0.5f)};
  const std::string xyz = PackXyz(points);
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

TEST(PackedCloud, UnpackInvertsPackBitForBit) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Points points = {Eigen::Vector3f(1.0f, -2.5f, 0.125f), Eigen::Vector3f(nan, 3e-39f, -0.0f),
                         Eigen::Vector3f(1e30f, -1e-7f, 42.0f)};
  const std::string xyz = PackXyz(points);
  ASSERT_EQ(xyz.size(), 36u);
  const Points back = UnpackXyz(xyz);
  ASSERT_EQ(back.size(), points.size());
  EXPECT_EQ(std::memcmp(back.data(), points.data(), 36), 0);
  EXPECT_TRUE(PackXyz({}).empty());
  EXPECT_TRUE(UnpackXyz("").empty());
}

}  // namespace
}  // namespace tubepick
