#include "clients/cell/nudge.h"

#include <gtest/gtest.h>

#include <cmath>

#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

constexpr double kR = 0.0125;
// The tool goes up kLift after the push, and comes down from (and goes back up to) kTransitZ.
constexpr double kLift = 0.1, kTransitZ = 0.5;

v1::Tube StraightTube(std::uint32_t id, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      v1::Occlusion occlusion = v1::OCCLUSION_NONE) {
  v1::Tube tube;
  tube.set_id(id);
  tube.set_occlusion(occlusion);
  v1::Cylinder* c = tube.add_cylinders();
  *c->mutable_start() = ToProto(a);
  *c->mutable_end() = ToProto(b);
  c->set_radius(kR);
  return tube;
}

class NudgeTest : public ::testing::Test {
 protected:
  CellConfig cell;  // bin 0.8 × 0.6 × 0.2 m: walls at x = ±0.4, y = ±0.3
  ToolGeometry tool;
  NudgeParams params;
  google::protobuf::RepeatedPtrField<v1::Tube> tubes;
};

TEST_F(NudgeTest, TubeAlongTheMinusYWallIsPushedStraightOffIt) {
  // Axis 23.5 mm from the wall (11 mm between tube and wall): the last tube of a failed PVC round.
  *tubes.Add() = StraightTube(4, {-0.25, -0.2765, kR}, {0.25, -0.2765, kR});
  const auto plan = PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->tube_id, 4u);
  EXPECT_NEAR(plan->direction.y(), 1.0, 1e-12);
  EXPECT_NEAR(plan->wall_distance, 0.0235, 1e-9);
  EXPECT_NEAR(std::abs(plan->p_Bin_contact.x()), 0.0, 0.011);  // try 0: the tube's middle
  // push_gain · (0.15 − 0.0235) = 0.253, clamped to max_push.
  EXPECT_NEAR(plan->distance, params.max_push, 1e-12);
  // The closed, tilted tool clears the wall and the floor at the press, along the push and up.
  EXPECT_FALSE(ToolClearanceProblem(cell, tool, plan->X_BinTcpPress, 0.0,
                                    {Eigen::Vector3d::Zero(), plan->distance * plan->direction,
                                     plan->distance * plan->direction + Eigen::Vector3d(0, 0, 0.1)}));
  // x_Tcp along the push (the housing's narrow side faces the wall), z_Tcp down and towards the
  // wall by the tilt.
  const Eigen::Matrix3d R = plan->X_BinTcpPress.linear();
  EXPECT_NEAR(R.col(2).z(), -std::cos(params.tilt), 1e-9);
  EXPECT_NEAR(R.col(2).y(), -std::sin(params.tilt), 1e-9);
  EXPECT_TRUE(R.col(1).isApprox(Eigen::Vector3d::UnitX(), 1e-12));  // closing along the wall
  // The pads' bottom is press_depth below the tube's top, and the pads still cover it.
  const Eigen::Vector3d tip = plan->X_BinTcpPress * Eigen::Vector3d(0, 0, tool.finger_tip_depth);
  EXPECT_NEAR(tip.z(), 2.0 * kR - params.press_depth, 1e-9);
  EXPECT_LE(plan->shift, 0.5 * tool.finger_size.x() + 0.5 * kR + 1e-9);
  // Further tries push elsewhere along the tube: 0.3 and 0.7 of its length.
  EXPECT_NEAR(PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 1)->p_Bin_contact.x(), -0.25 + 0.3 * 0.5,
              0.011);
  EXPECT_NEAR(PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 2)->p_Bin_contact.x(), -0.25 + 0.7 * 0.5,
              0.011);
}

TEST_F(NudgeTest, TubeInACornerIsPushedDiagonally) {
  // Along the +x wall (8 cm from it), its upper end 5 cm from the +y wall.
  *tubes.Add() = StraightTube(0, {0.32, 0.0, kR}, {0.32, 0.25, kR});
  params.near_wall_distance = 0.09;
  const auto plan =
      PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 2);  // 0.7 of the length: y = 0.175
  ASSERT_TRUE(plan);
  EXPECT_NEAR(plan->direction.x(), -1.0, 1e-12);  // only the +x wall is within 9 cm of y = 0.175
  params.near_wall_distance = 0.16;
  const auto corner = PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 2);
  ASSERT_TRUE(corner);
  EXPECT_NEAR(corner->direction.x(), -std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(corner->direction.y(), -std::sqrt(0.5), 1e-9);
}

TEST_F(NudgeTest, NoNudgeForTubesAwayFromTheWallsOrWithoutGeometry) {
  *tubes.Add() = StraightTube(0, {-0.2, 0.0, kR}, {0.2, 0.0, kR});
  tubes.Add()->set_id(1);  // no cylinders
  EXPECT_FALSE(PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0));
}

TEST_F(NudgeTest, NonOccludedTubesGoFirstThenTheClosestToAWall) {
  *tubes.Add() = StraightTube(0, {-0.2, 0.28, kR}, {0.2, 0.28, kR}, v1::OCCLUSION_WEAK);
  *tubes.Add() = StraightTube(1, {-0.2, -0.25, kR}, {0.2, -0.25, kR});
  *tubes.Add() = StraightTube(2, {-0.2, -0.26, 3 * kR}, {0.2, -0.26, 3 * kR});
  EXPECT_EQ(PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0)->tube_id, 2u);
}

TEST_F(NudgeTest, APushStopsShortOfTheNextTube) {
  // The tube along the -y wall of the first test, and another on the floor 20 cm further in: the full
  // push (0.22 m) would drive the pads into it.
  *tubes.Add() = StraightTube(4, {-0.25, -0.2765, kR}, {0.25, -0.2765, kR});
  *tubes.Add() = StraightTube(5, {-0.25, -0.0765, kR}, {0.25, -0.0765, kR});
  const auto plan = PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->tube_id, 4u);
  EXPECT_GE(plan->distance, params.min_push);
  EXPECT_LT(plan->distance, params.max_push - 0.03);
  // At the end of the push every tool box stays tube_clearance from the other tube's surface.
  const Eigen::Vector3d end = plan->distance * plan->direction;
  for (const ToolBox& box : ToolBoxes(tool, 0.0))
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d offset((corner & 1 ? 1 : -1) * box.half_size.x(),
                                   (corner & 2 ? 1 : -1) * box.half_size.y(),
                                   (corner & 4 ? 1 : -1) * box.half_size.z());
      const Eigen::Vector3d p = plan->X_BinTcpPress * (box.centre_Tcp + offset) + end;
      const double to_axis = std::hypot(p.y() + 0.0765, p.z() - kR);
      EXPECT_TRUE(p.y() < -0.0765 - kR - params.tube_clearance + 1e-9 || to_axis > kR + params.tube_clearance)
          << box.part << " corner " << corner << " at (" << p.transpose() << ")";
    }
  // Without the other tube the push is the full one.
  tubes.RemoveLast();
  EXPECT_NEAR(PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0)->distance, params.max_push, 1e-12);
}

TEST_F(NudgeTest, ATubeTooCloseInFrontIsPushedInsteadAndOneInTheWayMovesTheContact) {
  // A second tube 4 cm further in along the whole wall: no push of the outer tube gets min_push far,
  // so the inner one (along the wall too) is pushed.
  *tubes.Add() = StraightTube(4, {-0.25, -0.2765, kR}, {0.25, -0.2765, kR});
  *tubes.Add() = StraightTube(5, {-0.25, -0.2365, kR}, {0.25, -0.2365, kR});
  const auto inner = PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0);
  ASSERT_TRUE(inner);
  EXPECT_EQ(inner->tube_id, 5u);
  EXPECT_NEAR(inner->distance, params.push_gain * (params.target_wall_distance - 0.0635), 1e-9);  // not cut

  // A tube across the outer one's middle, 6 cm up on the heap, its end 11 cm from the wall (not along
  // it): a push at the middle would drive the tool into it, so the outer tube is pressed elsewhere.
  tubes.RemoveLast();
  *tubes.Add() = StraightTube(6, {0.0, -0.19, 0.06}, {0.0, 0.1, 0.06});
  const auto beside = PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0);
  ASSERT_TRUE(beside);
  EXPECT_EQ(beside->tube_id, 4u);
  EXPECT_GT(std::abs(beside->p_Bin_contact.x()), 0.05);
}

TEST_F(NudgeTest, TheWayDownFromTheTransitHeightMustBeClear) {
  // The tube along the -y wall, and a short one over its middle on the heap 0.32 m up: above what
  // the tool sweeps from the press to kLift over it, but in the way of its descent from kTransitZ.
  *tubes.Add() = StraightTube(4, {-0.25, -0.2765, kR}, {0.25, -0.2765, kR});
  *tubes.Add() = StraightTube(6, {-0.08, -0.25, 0.32}, {0.08, -0.25, 0.32});
  const auto plan = PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->tube_id, 4u);
  EXPECT_GT(std::abs(plan->p_Bin_contact.x()), 0.05);
  // Coming down from just above the lift, the middle is free.
  EXPECT_LT(std::abs(PlanNudge(tubes, cell, tool, params, kLift, 0.0, 0)->p_Bin_contact.x()), 0.011);
}

TEST_F(NudgeTest, ABranchOfThePressedTreeAboveTheContactMovesIt) {
  // A tree along the -y wall on the floor whose branch rises to 0.15 m, leaning over the trunk from
  // the point the first nudge presses (half the tree's length along it: x = half the branch's
  // length). Pressed there, the tool would come down through the branch.
  const Eigen::Vector3d rise(0.0, 0.0565, 0.15 - kR);
  const double x_root = 0.5 * rise.norm();
  v1::Tube tree = StraightTube(4, {-0.25, -0.2765, kR}, {0.25, -0.2765, kR});
  v1::Cylinder* branch = tree.add_cylinders();
  *branch->mutable_start() = ToProto(Eigen::Vector3d(x_root, -0.2765, kR));
  *branch->mutable_end() = ToProto(Eigen::Vector3d(x_root, -0.2765, kR) + rise);
  branch->set_radius(kR);
  *tubes.Add() = tree;
  const auto plan = PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->tube_id, 4u);
  EXPECT_LT(plan->p_Bin_contact.z(), 2.0 * kR);  // on the trunk, not up the branch
  EXPECT_GT(std::abs(plan->p_Bin_contact.x() - x_root), 0.05);
  // The same tree with the branch lying flat on the floor is pressed at the root.
  *tubes.Mutable(0)->mutable_cylinders(1)->mutable_end() =
      ToProto(Eigen::Vector3d(x_root, -0.2765 + rise.norm(), kR));
  EXPECT_LT(std::abs(PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0)->p_Bin_contact.x() - x_root),
            0.011);
}

TEST_F(NudgeTest, TubeTooDeepInTheCornerOfFloorAndWallIsLeftAlone) {
  // Touching the wall: the pads cannot cover its top without the tool reaching into the wall.
  *tubes.Add() = StraightTube(0, {-0.2, -0.3 + kR, kR}, {0.2, -0.3 + kR, kR});
  params.tilt = 0.0;
  EXPECT_FALSE(PlanNudge(tubes, cell, tool, params, kLift, kTransitZ, 0));
}

}  // namespace
}  // namespace tubepick::cell
