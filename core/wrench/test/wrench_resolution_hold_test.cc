#include "core/wrench/resolution_hold.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

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

TEST(PayloadOnTool, ReadsTheWeightAndWhereItHangs) {
  const Eigen::Isometry3d X = LiftPose({0.3, -0.1, 0.5});
  const Payload payload =
      PayloadOnTool(kReference, Loaded(kReference, X, 1.6, {-0.12, 0.07, -0.3}), X.linear());
  EXPECT_NEAR(payload.weight, 1.6, 1e-12);
  EXPECT_NEAR(payload.p_TcpPayload_Bin.x(), -0.12, 1e-12);
  EXPECT_NEAR(payload.p_TcpPayload_Bin.y(), 0.07, 1e-12);
  // The tool pushed up by 0.5 N: a negative weight and no lever arm.
  const Payload pressing =
      PayloadOnTool(kReference, Loaded(kReference, X, -0.5, {0.1, 0.1, 0.0}), X.linear());
  EXPECT_NEAR(pressing.weight, -0.5, 1e-12);
  EXPECT_EQ(pressing.p_TcpPayload_Bin, Eigen::Vector3d::Zero());
  Wrench bad = kReference;
  bad.force.z() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(PayloadOnTool(kReference, bad, X.linear()), InvalidArgument);
  EXPECT_THROW(PayloadOnTool(kReference, kReference, 2.0 * X.linear()), InvalidArgument);
}

TEST(PutBackShift, MovesACentreOfMassAtAWallOnlyAsFarInsideAsTheMarginAsks) {
  // Seed 14's tangle (2026-12-05): TCP at x = 0.21 m, its centre of mass 0.18 m further along +x,
  // 1 cm inside the +x wall of a 0.8 m bin. With a 0.15 m margin it goes to x = 0.25 m.
  const Eigen::Vector3d shift = PlanPutBackShift({0.21, 0.05, 0.45}, {0.18, -0.18, 0.0}, kBin, 0.15);
  EXPECT_NEAR(shift.x(), 0.25 - 0.39, 1e-12);
  // y: 0.05 - 0.18 = -0.13, inside |y| <= 0.15: not moved.
  EXPECT_EQ(shift.y(), 0.0);
  EXPECT_EQ(shift.z(), 0.0);
  // Already inside on both axes: no move at all (the put-back lays it where it came from).
  EXPECT_EQ(PlanPutBackShift({0.1, 0.05, 0.45}, {0.05, 0.02, 0.0}, kBin, 0.15), Eigen::Vector3d::Zero());
  // Past the -y wall (y = -0.35) back to y = -0.15.
  EXPECT_NEAR(PlanPutBackShift({0.0, -0.2, 0.45}, {0.0, -0.15, 0.0}, kBin, 0.15).y(), 0.2, 1e-12);
  // A bin narrower than two margins: to its middle.
  EXPECT_NEAR(PlanPutBackShift({0.0, 0.1, 0.45}, {0.0, 0.05, 0.0}, kBin, 0.4).y(), -0.15, 1e-12);
}

TEST(PutBackShift, NeverCarriesTheToolOutOfTheBinWhateverTheReadingSays) {
  // Seed 14 of the 20-tree bins (2026-12-07): after a resolution motion the F/T read 1.66 N with
  // 1.9 N·m of torque, a centre of mass 1.23 m to the TCP's -y side, past the -y wall. Clamping
  // that centre alone moved the TCP 1.11 m along +y, over the +y wall, and the tangle was put
  // down outside the bin. The TCP now stops 0.15 m inside the +y wall.
  const Eigen::Vector3d shift = PlanPutBackShift({-0.16, -0.035, 0.45}, {0.04, -1.23, 0.0}, kBin, 0.15);
  EXPECT_NEAR(-0.035 + shift.y(), 0.15, 1e-12);
  EXPECT_EQ(shift.x(), 0.0);
  // A TCP already nearer a wall than the margin is not moved further out by it either.
  EXPECT_NEAR(0.25 + PlanPutBackShift({0.0, 0.25, 0.45}, {0.0, -0.9, 0.0}, kBin, 0.15).y(), 0.25, 1e-12);
}

TEST(PutBackShift, ACentreOfMassBeyondATubesLengthHangsFromNothing) {
  Payload payload;
  payload.weight = 1.64;
  payload.p_TcpPayload_Bin = Eigen::Vector3d(0.04, -1.23, 0.0);  // seed 14's reading
  EXPECT_FALSE(HangsFromTheTool(payload, 0.75));
  EXPECT_TRUE(HangsFromTheTool(payload, 0.0));  // the tube length unknown: not judged
  payload.p_TcpPayload_Bin = Eigen::Vector3d(0.3, -0.2, 0.0);
  EXPECT_TRUE(HangsFromTheTool(payload, 0.75));
  EXPECT_FALSE(HangsFromTheTool(payload, 0.3));
}

TEST(PutBackShift, RejectsANegativeMarginByName) {
  try {
    PlanPutBackShift({0.0, 0.0, 0.4}, {0.0, 0.0, 0.0}, kBin, -0.1);
    FAIL() << "a negative margin was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("put_back_margin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PlanPutBackShift({std::nan(""), 0.0, 0.4}, {0.0, 0.0, 0.0}, kBin, 0.1), InvalidArgument);
}

}  // namespace
}  // namespace tubepick
