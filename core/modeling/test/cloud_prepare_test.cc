#include "core/modeling/cloud_prepare.h"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kTol = 1e-6;  // metres; float rounding of sub-metre coordinates

Eigen::Isometry3d TiltedSensorPose() {
  Eigen::Isometry3d X_BinSensor = Eigen::Isometry3d::Identity();
  X_BinSensor.linear() =
      (Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  X_BinSensor.translation() = Eigen::Vector3d(0.1, -0.05, 1.2);
  return X_BinSensor;
}

TEST(PrepareCloud, TransformsIntoTheBinFrame) {
  // Default mount: 1.1 m above the floor centre, looking down (x right, y down, z forward).
  const Points points_Sensor = {Eigen::Vector3f(0.0f, 0.0f, 1.1f), Eigen::Vector3f(0.1f, 0.2f, 1.0f)};
  const PreparedCloud prepared =
      PrepareCloud(points_Sensor, LengthUnit::kMetre, SensorConfig::DefaultX_BinSensor());
  ASSERT_EQ(prepared.points_Bin.size(), 2u);
  EXPECT_LT(prepared.points_Bin[0].norm(), kTol);
  EXPECT_LT((prepared.points_Bin[1] - Eigen::Vector3f(0.1f, -0.2f, 0.1f)).norm(), kTol);
  EXPECT_EQ(prepared.dropped_non_finite, 0u);
}

TEST(PrepareCloud, MillimetresAndMetresGiveTheSameBinPoints) {
  const Points points_m = {Eigen::Vector3f(0.01f, -0.2f, 1.05f), Eigen::Vector3f(-0.3f, 0.25f, 0.9f),
                           Eigen::Vector3f(0.0f, 0.0f, 1.2f)};
  Points points_mm;
  for (const Eigen::Vector3f& p : points_m) points_mm.push_back(1000.0f * p);
  const Eigen::Isometry3d X_BinSensor = TiltedSensorPose();
  const PreparedCloud from_m = PrepareCloud(points_m, LengthUnit::kMetre, X_BinSensor);
  const PreparedCloud from_mm = PrepareCloud(points_mm, LengthUnit::kMillimetre, X_BinSensor);
  ASSERT_EQ(from_m.points_Bin.size(), points_m.size());
  ASSERT_EQ(from_mm.points_Bin.size(), points_m.size());
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    EXPECT_LT((from_m.points_Bin[i] - from_mm.points_Bin[i]).norm(), kTol) << "point " << i;
    const Eigen::Vector3d expected = X_BinSensor * points_m[i].cast<double>();
    EXPECT_LT((from_m.points_Bin[i].cast<double>() - expected).norm(), kTol) << "point " << i;
  }
}

TEST(PrepareCloud, DropsAndCountsNonFinitePoints) {
  const Points points_Sensor = {Eigen::Vector3f(0.0f, 0.0f, 1.0f),  Eigen::Vector3f(kNaN, 0.0f, 1.0f),
                                Eigen::Vector3f(0.1f, 0.0f, 1.0f),  Eigen::Vector3f(0.0f, kInf, 1.0f),
                                Eigen::Vector3f(0.0f, 0.0f, -kInf), Eigen::Vector3f(0.2f, 0.0f, 1.0f)};
  const PreparedCloud prepared =
      PrepareCloud(points_Sensor, LengthUnit::kMetre, Eigen::Isometry3d::Identity());
  EXPECT_EQ(prepared.dropped_non_finite, 3u);
  ASSERT_EQ(prepared.points_Bin.size(), 3u);
  // The finite points keep their order.
  EXPECT_FLOAT_EQ(prepared.points_Bin[0].x(), 0.0f);
  EXPECT_FLOAT_EQ(prepared.points_Bin[1].x(), 0.1f);
  EXPECT_FLOAT_EQ(prepared.points_Bin[2].x(), 0.2f);
}

TEST(PrepareCloud, EmptyCloudIsAnError) {
  try {
    PrepareCloud({}, LengthUnit::kMetre, Eigen::Isometry3d::Identity());
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("0 points"));
  }
}

TEST(PrepareCloud, AllNonFiniteIsAnError) {
  const Points points_Sensor(5, Eigen::Vector3f(kNaN, kNaN, kNaN));
  try {
    PrepareCloud(points_Sensor, LengthUnit::kMillimetre, Eigen::Isometry3d::Identity());
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("5 points arrived"));
    EXPECT_THAT(e.what(), HasSubstr("5 of them were non-finite"));
  }
}

}  // namespace
}  // namespace tubepick
