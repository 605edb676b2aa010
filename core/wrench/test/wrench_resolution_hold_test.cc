#include "core/wrench/resolution_hold.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/common/errors.h"

namespace tubepick {
namespace {

const Eigen::Vector3d kBin(0.8, 0.6, 0.2);

// The lift pose: TCP z down (a half turn about x), yawed 30°, at `p`.
Eigen::Isometry3d LiftPose(const Eigen::Vector3d& p) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = (Eigen::AngleAxisd(M_PI / 6.0, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  X.translation() = p;
  return X;
}

// The reading of a payload of weight `w` newtons hanging at `r_Bin` from the TCP, in the sensor
// (TCP) axes, on top of `reference`.
Wrench Loaded(const Wrench& reference, const Eigen::Isometry3d& X_BinTcp, double w,
              const Eigen::Vector3d& r_Bin) {
  const Eigen::Vector3d force_Bin(0.0, 0.0, -w);
  const Eigen::Matrix3d R_TcpBin = X_BinTcp.linear().transpose();
  return Wrench{reference.force + R_TcpBin * force_Bin, reference.torque + R_TcpBin * r_Bin.cross(force_Bin)};
}

const Wrench kReference{{0.4, -0.3, 1.2}, {0.02, -0.01, 0.005}};

TEST(ResolutionHold, BringsThePayloadsCentreOfMassOverTheBinsMiddle) {
  const Eigen::Isometry3d X = LiftPose({0.2, 0.1, 0.5});
  const ResolutionHold hold =
      PlanResolutionHold(kReference, Loaded(kReference, X, 1.1, {0.1, -0.05, -0.2}), X, kBin, 0.15);
  EXPECT_NEAR(hold.p_TcpPayload_Bin.x(), 0.1, 1e-12);
  EXPECT_NEAR(hold.p_TcpPayload_Bin.y(), -0.05, 1e-12);
  EXPECT_EQ(hold.p_TcpPayload_Bin.z(), 0.0);
  // TCP to (−0.1, 0.05): the payload's centre of mass at (0, 0).
  EXPECT_NEAR(hold.shift_Bin.x(), -0.3, 1e-12);
  EXPECT_NEAR(hold.shift_Bin.y(), -0.05, 1e-12);
  EXPECT_EQ(hold.shift_Bin.z(), 0.0);
}

TEST(ResolutionHold, KeepsTheTcpTheWallMarginInsideTheBin) {
  const Eigen::Isometry3d X = LiftPose({-0.1, 0.0, 0.45});
  // A payload 0.4 m along +x and 0.3 m along -y: its centre of mass cannot reach the middle with
  // the TCP 0.15 m inside the walls (|x| <= 0.25, |y| <= 0.15).
  const ResolutionHold hold =
      PlanResolutionHold(kReference, Loaded(kReference, X, 2.0, {0.4, -0.3, -0.1}), X, kBin, 0.15);
  EXPECT_NEAR(hold.shift_Bin.x(), -0.25 - (-0.1), 1e-12);
  EXPECT_NEAR(hold.shift_Bin.y(), 0.15, 1e-12);
  // A bin narrower than two margins: the TCP goes to its middle.
  const ResolutionHold narrow =
      PlanResolutionHold(kReference, Loaded(kReference, X, 2.0, {0.4, -0.3, -0.1}), X, kBin, 0.5);
  EXPECT_NEAR(narrow.shift_Bin.x(), 0.1, 1e-12);
  EXPECT_NEAR(narrow.shift_Bin.y(), 0.0, 1e-12);
}

TEST(ResolutionHold, NoWeightGainedLeavesNoLeverArm) {
  const Eigen::Isometry3d X = LiftPose({0.1, -0.1, 0.5});
  const ResolutionHold hold = PlanResolutionHold(kReference, kReference, X, kBin, 0.15);
  EXPECT_EQ(hold.p_TcpPayload_Bin, Eigen::Vector3d::Zero());
  EXPECT_NEAR(hold.shift_Bin.x(), -0.1, 1e-12);
  EXPECT_NEAR(hold.shift_Bin.y(), 0.1, 1e-12);
}

TEST(ResolutionHold, RejectsBadInputsByName) {
  const Eigen::Isometry3d X = LiftPose({0.0, 0.0, 0.5});
  Wrench bad = kReference;
  bad.torque.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(PlanResolutionHold(kReference, bad, X, kBin, 0.15), InvalidArgument);
  EXPECT_THROW(PlanResolutionHold(kReference, kReference, X, kBin, -0.01), InvalidArgument);
  try {
    PlanResolutionHold(kReference, kReference, X, kBin, -0.01);
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("resolution_wall_margin"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tubepick
