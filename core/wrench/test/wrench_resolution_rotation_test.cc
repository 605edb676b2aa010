#include "core/wrench/resolution_rotation.h"

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/testing/error_of.h"
#include "core/wrench/wrench.h"
#include "core/wrench/wrench_params.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;

constexpr double kDeg = M_PI / 180.0;
constexpr double kAngleTol = 1e-12;
constexpr double kVectorTol = 1e-12;
constexpr double kRotationTol = 1e-12;

// Reference readings with a non-zero offset, as a real sensor has.
Wrench Reference() {
  Wrench w;
  w.force = Eigen::Vector3d(0.2, -0.1, 4.0);
  w.torque = Eigen::Vector3d(0.01, -0.02, 0.003);
  return w;
}

// The reference plus `delta_torque`.
Wrench Current(const Eigen::Vector3d& delta_torque) {
  Wrench w = Reference();
  w.force.z() -= 1.5;
  w.torque += delta_torque;
  return w;
}

Eigen::Matrix3d Rotation(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

using tubepick::testing::ErrorOf;

TEST(ResolutionRotation, TorqueAlongYGivesAxisYAnd45Degrees) {
  const WrenchParams params;
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), Eigen::Isometry3d::Identity(), params);
  ASSERT_TRUE(plan.has_value());
  EXPECT_TRUE(plan->torque_axis_Tcp.isApprox(Eigen::Vector3d::UnitY(), kVectorTol));
  ASSERT_EQ(plan->motions.size(), 1u);
  const ResolutionMotion& motion = plan->motions[0];
  EXPECT_TRUE(motion.axis_Tcp.isApprox(Eigen::Vector3d::UnitY(), kVectorTol));
  EXPECT_NEAR(motion.angle, 45.0 * kDeg, kAngleTol);
  EXPECT_EQ(motion.yaw, 0.0);
  ASSERT_EQ(motion.waypoints.size(), 1u);
  const Eigen::Isometry3d& X_TcpTcpRotated = motion.waypoints[0].X_TcpTcpRotated;
  EXPECT_TRUE(
      X_TcpTcpRotated.linear().isApprox(Rotation(45.0 * kDeg, Eigen::Vector3d::UnitY()), kRotationTol));
  EXPECT_TRUE(X_TcpTcpRotated.translation().isZero(0.0));
  EXPECT_THAT(motion.description, HasSubstr("rotate +45.0 deg about the torque axis [0.000, 1.000, 0.000]"));
}

TEST(ResolutionRotation, VerticalTorqueIsDropped) {
  // Eq. 5.7: ΔM = [ΔMx, ΔMy, 0] whatever M_z does.
  const std::optional<ResolutionPlan> plan = PlanResolutionRotation(
      Reference(), Current({0.03, -0.04, 0.7}), Eigen::Isometry3d::Identity(), WrenchParams{});
  ASSERT_TRUE(plan.has_value());
  EXPECT_TRUE(plan->delta_torque_Tcp.isApprox(Eigen::Vector3d(0.03, -0.04, 0.0), kVectorTol));
  EXPECT_EQ(plan->delta_torque_Tcp.z(), 0.0);
  EXPECT_TRUE(plan->torque_axis_Tcp.isApprox(Eigen::Vector3d(0.6, -0.8, 0.0), kVectorTol));
}

TEST(ResolutionRotation, PayloadOffsetAlongXTiltsItDown) {
  // Sign check of the convention in wrench.h: a payload of weight W hanging at r = (0.1, 0, −0.05)
  // (TCP z up) exerts the torque r × (0, 0, −W) = (0, 0.1·W, 0) on the sensor. The thesis's positive
  // rotation about that axis lowers the payload, as it would swing if the gripper were released.
  constexpr double kWeight = 1.0;
  const Eigen::Vector3d r(0.1, 0.0, -0.05);
  const Eigen::Vector3d torque = r.cross(Eigen::Vector3d(0.0, 0.0, -kWeight));
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current(torque), Eigen::Isometry3d::Identity(), WrenchParams{});
  ASSERT_TRUE(plan.has_value());
  const Eigen::Vector3d r_rotated = plan->motions[0].waypoints[0].X_TcpTcpRotated * r;
  EXPECT_LT(r_rotated.z(), r.z());
}

TEST(ResolutionRotation, BinWaypointsRotateAboutTheTcp) {
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.linear() = Rotation(30.0 * kDeg, Eigen::Vector3d::UnitZ());
  X_BinTcp.translation() = Eigen::Vector3d(0.1, -0.2, 0.45);
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.05, 0.0, 0.0}), X_BinTcp, WrenchParams{});
  ASSERT_TRUE(plan.has_value());
  const ResolutionWaypoint& waypoint = plan->motions[0].waypoints[0];
  EXPECT_TRUE(waypoint.X_BinTcpRotated.isApprox(X_BinTcp * waypoint.X_TcpTcpRotated, kRotationTol));
  EXPECT_TRUE(waypoint.X_BinTcpRotated.translation().isApprox(X_BinTcp.translation(), kVectorTol));
  // The torque axis is TCP +x, i.e. 30° from bin +x.
  const Eigen::Matrix3d expected =
      Rotation(45.0 * kDeg, X_BinTcp.linear() * Eigen::Vector3d::UnitX()) * X_BinTcp.linear();
  EXPECT_TRUE(waypoint.X_BinTcpRotated.linear().isApprox(expected, kRotationTol));
}

TEST(ResolutionRotation, NegativeVariantRotatesMinus45) {
  WrenchParams params;
  params.variant = ResolutionVariant::kTorqueAxisNegative;
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), Eigen::Isometry3d::Identity(), params);
  ASSERT_TRUE(plan.has_value());
  ASSERT_EQ(plan->motions.size(), 1u);
  EXPECT_TRUE(plan->motions[0].axis_Tcp.isApprox(Eigen::Vector3d::UnitY(), kVectorTol));
  EXPECT_NEAR(plan->motions[0].angle, -45.0 * kDeg, kAngleTol);
  EXPECT_TRUE(plan->motions[0].waypoints[0].X_TcpTcpRotated.linear().isApprox(
      Rotation(-45.0 * kDeg, Eigen::Vector3d::UnitY()), kRotationTol));
  EXPECT_THAT(plan->motions[0].description, HasSubstr("-45.0 deg"));
}

TEST(ResolutionRotation, PerpendicularVariantOffersBothSigns) {
  WrenchParams params;
  params.variant = ResolutionVariant::kPerpendicular;
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), Eigen::Isometry3d::Identity(), params);
  ASSERT_TRUE(plan.has_value());
  ASSERT_EQ(plan->motions.size(), 2u);
  // z × y = −x: horizontal and perpendicular to ΔM.
  const Eigen::Vector3d expected_axis(-1.0, 0.0, 0.0);
  EXPECT_TRUE(plan->motions[0].axis_Tcp.isApprox(expected_axis, kVectorTol));
  EXPECT_TRUE(plan->motions[1].axis_Tcp.isApprox(expected_axis, kVectorTol));
  EXPECT_NEAR(plan->motions[0].angle, 45.0 * kDeg, kAngleTol);
  EXPECT_NEAR(plan->motions[1].angle, -45.0 * kDeg, kAngleTol);
  EXPECT_TRUE(plan->motions[1].waypoints[0].X_TcpTcpRotated.linear().isApprox(
      Rotation(-45.0 * kDeg, expected_axis), kRotationTol));
  EXPECT_THAT(plan->motions[0].description, HasSubstr("perpendicular to the torque"));
}

// The torque axis first (the thesis' motion), then the perpendicular's +angle only: its −angle,
// after a +angle, swung the payload 110° and threw trees out of the bin in the trials.
TEST(ResolutionRotation, TorqueAxisThenPerpendicularTiltsAboutBothAxesWithTheSameSign) {
  WrenchParams params;
  params.variant = ResolutionVariant::kTorqueAxisThenPerpendicular;
  params.rotation_angle = 55.0 * kDeg;
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), Eigen::Isometry3d::Identity(), params);
  ASSERT_TRUE(plan.has_value());
  ASSERT_EQ(plan->motions.size(), 2u);
  EXPECT_TRUE(plan->motions[0].axis_Tcp.isApprox(Eigen::Vector3d::UnitY(), kVectorTol));
  EXPECT_TRUE(plan->motions[1].axis_Tcp.isApprox(Eigen::Vector3d(-1.0, 0.0, 0.0), kVectorTol));
  EXPECT_NEAR(plan->motions[0].angle, 55.0 * kDeg, kAngleTol);
  EXPECT_NEAR(plan->motions[1].angle, 55.0 * kDeg, kAngleTol);
  EXPECT_TRUE(plan->motions[1].waypoints[0].X_TcpTcpRotated.linear().isApprox(
      Rotation(55.0 * kDeg, Eigen::Vector3d(-1.0, 0.0, 0.0)), kRotationTol));
  EXPECT_THAT(plan->motions[0].description, HasSubstr("torque axis"));
  EXPECT_THAT(plan->motions[1].description, HasSubstr("perpendicular to the torque"));
}

TEST(ResolutionRotation, JointSafeYawAlignsTorqueWithConfiguredAxis) {
  WrenchParams params;
  params.variant = ResolutionVariant::kJointSafe;
  params.joint_safe_axis = Eigen::Vector3d::UnitX();
  params.joint_safe_min_yaw = false;
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), Eigen::Isometry3d::Identity(), params);
  ASSERT_TRUE(plan.has_value());
  ASSERT_EQ(plan->motions.size(), 1u);
  const ResolutionMotion& motion = plan->motions[0];
  // ΔM = +y turns with the gripper; a −90° yaw about z brings it onto +x.
  EXPECT_NEAR(motion.yaw, -90.0 * kDeg, kAngleTol);
  EXPECT_TRUE(motion.axis_Tcp.isApprox(Eigen::Vector3d::UnitX(), kVectorTol));
  EXPECT_NEAR(motion.angle, 45.0 * kDeg, kAngleTol);
  ASSERT_EQ(motion.waypoints.size(), 2u);
  const Eigen::Matrix3d R_yaw = Rotation(-90.0 * kDeg, Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(motion.waypoints[0].X_TcpTcpRotated.linear().isApprox(R_yaw, kRotationTol));
  EXPECT_TRUE((R_yaw * plan->torque_axis_Tcp).isApprox(Eigen::Vector3d::UnitX(), kVectorTol));
  const Eigen::Matrix3d R_final = motion.waypoints[1].X_TcpTcpRotated.linear();
  EXPECT_TRUE(R_final.isApprox(Rotation(45.0 * kDeg, Eigen::Vector3d::UnitX()) * R_yaw, kRotationTol));
  // Relative to the payload it is the thesis's tilt: yaw then +45° about ΔM in the gripper.
  EXPECT_TRUE(R_final.isApprox(R_yaw * Rotation(45.0 * kDeg, plan->torque_axis_Tcp), kRotationTol));
  EXPECT_TRUE(motion.waypoints[1].X_TcpTcpRotated.translation().isZero(0.0));
  EXPECT_THAT(motion.description, HasSubstr("yaw -90.0 deg about the TCP vertical"));
}

TEST(ResolutionRotation, JointSafeMinYawAlignsWithNegativeAxis) {
  WrenchParams params;
  params.variant = ResolutionVariant::kJointSafe;
  // ΔM at 135°: onto +x needs −135°, onto −x only +45°.
  const Eigen::Vector3d delta = 0.05 * Eigen::Vector3d(-1.0, 1.0, 0.0).normalized();
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current(delta), Eigen::Isometry3d::Identity(), params);
  ASSERT_TRUE(plan.has_value());
  const ResolutionMotion& motion = plan->motions[0];
  EXPECT_NEAR(motion.yaw, 45.0 * kDeg, kAngleTol);
  EXPECT_NEAR(motion.angle, -45.0 * kDeg, kAngleTol);
  const Eigen::Matrix3d R_yaw = Rotation(motion.yaw, Eigen::Vector3d::UnitZ());
  EXPECT_TRUE((R_yaw * plan->torque_axis_Tcp).isApprox(-Eigen::Vector3d::UnitX(), kVectorTol));
  EXPECT_TRUE(motion.waypoints[1].X_TcpTcpRotated.linear().isApprox(
      R_yaw * Rotation(45.0 * kDeg, plan->torque_axis_Tcp), kRotationTol));

  params.joint_safe_min_yaw = false;
  const std::optional<ResolutionPlan> plain =
      PlanResolutionRotation(Reference(), Current(delta), Eigen::Isometry3d::Identity(), params);
  ASSERT_TRUE(plain.has_value());
  EXPECT_NEAR(plain->motions[0].yaw, -135.0 * kDeg, kAngleTol);
  EXPECT_NEAR(plain->motions[0].angle, 45.0 * kDeg, kAngleTol);
}

TEST(ResolutionRotation, JointSafeAxisFixedInBin) {
  WrenchParams params;
  params.variant = ResolutionVariant::kJointSafe;
  params.joint_safe_frame = JointSafeFrame::kBin;
  params.joint_safe_axis = Eigen::Vector3d::UnitX();
  params.joint_safe_min_yaw = false;
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.linear() = Rotation(90.0 * kDeg, Eigen::Vector3d::UnitZ());
  X_BinTcp.translation() = Eigen::Vector3d(0.2, 0.1, 0.4);
  // ΔM along TCP +x = bin +y; bin +x is TCP −y: yaw −90°.
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.05, 0.0, 0.0}), X_BinTcp, params);
  ASSERT_TRUE(plan.has_value());
  const ResolutionMotion& motion = plan->motions[0];
  EXPECT_NEAR(motion.yaw, -90.0 * kDeg, kAngleTol);
  EXPECT_TRUE(motion.axis_Tcp.isApprox(Eigen::Vector3d(0.0, -1.0, 0.0), kVectorTol));
  // In the bin: the tilt is about bin +x through the TCP.
  const Eigen::Matrix3d R_BinTcpYawed = X_BinTcp.linear() * Rotation(motion.yaw, Eigen::Vector3d::UnitZ());
  const ResolutionWaypoint& last = motion.waypoints.back();
  EXPECT_TRUE(last.X_BinTcpRotated.linear().isApprox(
      Rotation(45.0 * kDeg, Eigen::Vector3d::UnitX()) * R_BinTcpYawed, kRotationTol));
  EXPECT_TRUE(last.X_BinTcpRotated.translation().isApprox(X_BinTcp.translation(), kVectorTol));
}

TEST(ResolutionRotation, TooSmallTorqueHasNoAxis) {
  const WrenchParams params;  // min_torque 0.005 N·m
  EXPECT_FALSE(PlanResolutionRotation(Reference(), Current({0.003, 0.0039, 0.0}),
                                      Eigen::Isometry3d::Identity(), params)
                   .has_value());
  // A purely vertical change has no horizontal axis.
  EXPECT_FALSE(
      PlanResolutionRotation(Reference(), Current({0.0, 0.0, 1.0}), Eigen::Isometry3d::Identity(), params)
          .has_value());
  EXPECT_TRUE(PlanResolutionRotation(Reference(), Current({0.003, 0.0041, 0.0}),
                                     Eigen::Isometry3d::Identity(), params)
                  .has_value());
}

TEST(ResolutionRotation, UpsideDownTcpNeedsMatchingUp) {
  // TCP z pointing down (approach direction): the default up_Tcp = +z is rejected ...
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.linear() = Rotation(180.0 * kDeg, Eigen::Vector3d::UnitX());
  WrenchParams params;
  EXPECT_THAT(ErrorOf([&] {
                PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), X_BinTcp, params);
              }),
              HasSubstr("X_BinTcp: wrench.up_Tcp [0.000, 0.000, 1.000] points [0.000, 0.000, -1.000]"));
  // ... and up_Tcp = −z works; the tilt is still about ΔM.
  params.up_Tcp = Eigen::Vector3d(0.0, 0.0, -1.0);
  const std::optional<ResolutionPlan> plan =
      PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), X_BinTcp, params);
  ASSERT_TRUE(plan.has_value());
  EXPECT_TRUE(plan->motions[0].axis_Tcp.isApprox(Eigen::Vector3d::UnitY(), kVectorTol));
}

TEST(ResolutionRotation, NonFiniteTorqueRejected) {
  Wrench current = Current({0.0, 0.05, 0.0});
  current.torque.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(ErrorOf([&] {
                PlanResolutionRotation(Reference(), current, Eigen::Isometry3d::Identity(), WrenchParams{});
              }),
              HasSubstr("current.torque: must be finite"));
}

TEST(ResolutionRotation, NonRigidLiftPoseRejected) {
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.linear() *= 2.0;
  EXPECT_THAT(ErrorOf([&] {
                PlanResolutionRotation(Reference(), Current({0.0, 0.05, 0.0}), X_BinTcp, WrenchParams{});
              }),
              HasSubstr("X_BinTcp: rotation is not proper orthonormal"));
}

}  // namespace
}  // namespace tubepick
