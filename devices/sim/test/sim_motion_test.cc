#include "devices/sim/sim_motion.h"

#include <cmath>

#include <gtest/gtest.h>

#include "devices/sim/sim_tubes.h"

namespace tubepick::devices::sim {
namespace {

constexpr double kTol = 1e-12;

TEST(TrapezoidProfile, AcceleratesCruisesAndStops) {
  // 1 m at 0.25 m/s with 0.5 m/s²: 0.5 s ramps of 6.25 cm each, 3.5 s cruise.
  const TrapezoidProfile profile(1.0, 0.25, 0.5);
  EXPECT_NEAR(profile.duration(), 4.5, kTol);
  EXPECT_NEAR(profile.DistanceAt(0.5), 0.0625, kTol);
  EXPECT_NEAR(profile.DistanceAt(2.25), 0.5, kTol);
  EXPECT_NEAR(profile.DistanceAt(4.0), 1.0 - 0.0625, kTol);
  EXPECT_DOUBLE_EQ(profile.DistanceAt(10.0), 1.0);
  EXPECT_DOUBLE_EQ(profile.DistanceAt(-1.0), 0.0);
}

TEST(TrapezoidProfile, ShortPathIsATriangle) {
  // 1 cm never reaches 1 m/s at 0.5 m/s²: peak √(0.01·0.5) m/s after √(0.01/0.5) s.
  const TrapezoidProfile profile(0.01, 1.0, 0.5);
  EXPECT_NEAR(profile.duration(), 2.0 * std::sqrt(0.02), kTol);
  EXPECT_NEAR(profile.DistanceAt(std::sqrt(0.02)), 0.005, kTol);
  EXPECT_DOUBLE_EQ(TrapezoidProfile(0.0, 1.0, 1.0).duration(), 0.0);
}

TEST(PoseSegment, InterpolatesTranslationAndSlerpsRotation) {
  const Eigen::Isometry3d from = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d to = Eigen::Isometry3d::Identity();
  to.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  to.translation() = Eigen::Vector3d(1.0, 2.0, 3.0);
  const PoseSegment segment(from, to);
  EXPECT_NEAR(segment.angle(), M_PI / 2, 1e-12);
  EXPECT_NEAR(segment.distance(), std::sqrt(14.0), kTol);
  const Eigen::Isometry3d mid = segment.At(0.5);
  EXPECT_TRUE(mid.translation().isApprox(Eigen::Vector3d(0.5, 1.0, 1.5)));
  EXPECT_NEAR(Eigen::AngleAxisd(mid.linear()).angle(), M_PI / 4, 1e-12);
  EXPECT_TRUE(segment.At(1.0).isApprox(to, 1e-12));
}

TEST(Polyline, WalksByArcLength) {
  const Polyline path({{0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {1, 2, 0}});
  EXPECT_DOUBLE_EQ(path.length(), 3.0);
  EXPECT_TRUE(path.At(0.5).isApprox(Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_TRUE(path.At(2.0).isApprox(Eigen::Vector3d(1, 1, 0)));
  EXPECT_TRUE(path.At(5.0).isApprox(Eigen::Vector3d(1, 2, 0)));
}

TEST(TiltFromVertical, MeasuresFromStraightDown) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();  // z down
  EXPECT_NEAR(TiltFromVertical(X), 0.0, 1e-12);
  X.linear() = Eigen::AngleAxisd(M_PI / 3, Eigen::Vector3d::UnitY()) * X.linear();
  EXPECT_NEAR(TiltFromVertical(X), M_PI / 3, 1e-12);
}

TEST(ResamplePolyline, EqualArcLengthIncludingBothEnds) {
  const std::vector<Eigen::Vector3d> points = ResamplePolyline({{0, 0, 0}, {0.3, 0, 0}, {0.3, 0.1, 0}}, 5);
  ASSERT_EQ(points.size(), 5u);
  EXPECT_TRUE(points[1].isApprox(Eigen::Vector3d(0.1, 0, 0)));
  EXPECT_TRUE(points[3].isApprox(Eigen::Vector3d(0.3, 0.0, 0)));
  EXPECT_TRUE(points[4].isApprox(Eigen::Vector3d(0.3, 0.1, 0)));
}

}  // namespace
}  // namespace tubepick::devices::sim
