#include "core/common/tube_graph.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
constexpr double kR = 0.0125;

Cylinder Cyl(const Eigen::Vector3d& a, const Eigen::Vector3d& b, std::uint32_t segment = 0) {
  Cylinder c;
  c.start = a;
  c.end = b;
  c.radius = kR;
  c.segment_id = segment;
  return c;
}

// Two cylinders along x with a 2 cm joint: 0.10 + 0.02 + 0.10.
Tube LinearTube() {
  Tube t;
  t.cylinders = {Cyl({0, 0, kR}, {0.10, 0, kR}, 0), Cyl({0.12, 0, kR}, {0.22, 0, kR}, 1)};
  return t;
}

// A T: a trunk along x cut at x = 0.10 (node 1), and a branch along y that starts 3 cm from the
// node and is 0.10 long.
Tube TeeTube() {
  Tube t;
  t.cylinders = {Cyl({0, 0, kR}, {0.10, 0, kR}, 0), Cyl({0.10, 0, kR}, {0.20, 0, kR}, 0),
                 Cyl({0.10, 0.03, kR}, {0.10, 0.13, kR}, 1)};
  t.nodes = {TubeNode{{0, 0, kR}}, TubeNode{{0.10, 0, kR}}, TubeNode{{0.20, 0, kR}},
             TubeNode{{0.10, 0.13, kR}}};
  t.branches = {TubeBranch{0, 1, 0, 1}, TubeBranch{1, 2, 1, 1}, TubeBranch{1, 3, 2, 1}};
  return t;
}

TEST(TubeGraph, ALinearTubeIsOneBranchBetweenItsEnds) {
  const Tube t = LinearTube();
  EXPECT_FALSE(t.branched());
  ASSERT_EQ(BranchesOf(t).size(), 1u);
  EXPECT_EQ(BranchesOf(t)[0], (TubeBranch{0, 1, 0, 2}));
  const std::vector<TubeNode> nodes = NodesOf(t);
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_TRUE(nodes[0].p_Bin.isApprox(Eigen::Vector3d(0, 0, kR)));
  EXPECT_TRUE(nodes[1].p_Bin.isApprox(Eigen::Vector3d(0.22, 0, kR)));
  const std::vector<TubeJoint> joints = TubeJoints(t);
  ASSERT_EQ(joints.size(), 1u);  // joint i links cylinders[i].end to cylinders[i+1].start
  EXPECT_EQ(joints[0].cylinder_a, 0);
  EXPECT_EQ(joints[0].cylinder_b, 1);
  EXPECT_NEAR(joints[0].length(), 0.02, 1e-12);
  EXPECT_NEAR(t.length(), 0.22, 1e-12);
  EXPECT_EQ(NodeDegrees(t), (std::vector<std::uint32_t>{1, 1}));
  const Tube explicit_graph = WithExplicitGraph(t);
  EXPECT_EQ(explicit_graph.branches.size(), 1u);
  EXPECT_NEAR(explicit_graph.length(), t.length(), 1e-15);
}

TEST(TubeGraph, ATeeLinksItsBranchToTheJunctionAndCountsTheLinkInItsLength) {
  const Tube t = TeeTube();
  EXPECT_TRUE(t.branched());
  EXPECT_NO_THROW(ValidateTubeGraph(t, "tubes[0]"));
  EXPECT_EQ(NodeDegrees(t), (std::vector<std::uint32_t>{1, 3, 1, 1}));
  const std::vector<TubeJoint> joints = TubeJoints(t);
  ASSERT_EQ(joints.size(), 1u);  // the trunk's halves meet at the node: no link
  EXPECT_TRUE(joints[0].junction_link());
  EXPECT_EQ(joints[0].cylinder_a, -1);
  EXPECT_EQ(joints[0].cylinder_b, 2);
  EXPECT_NEAR(joints[0].length(), 0.03, 1e-12);
  EXPECT_NEAR(t.length(), 0.20 + 0.03 + 0.10, 1e-12);
  // Mass centre of the axis: trunk 0.2 m centred at x 0.1, link + branch 0.13 m centred at y 0.065.
  const Eigen::Vector3d centre = TubeMassCentre(t);
  EXPECT_NEAR(centre.x(), 0.10, 1e-12);
  EXPECT_NEAR(centre.y(), 0.13 * 0.065 / 0.33, 1e-12);
  // Axis pieces in branch order: cylinder 0; cylinder 1; link, cylinder 2.
  const std::vector<AxisPiece> pieces = TubeAxisPieces(t);
  ASSERT_EQ(pieces.size(), 4u);
  EXPECT_EQ(pieces[0].cylinder, 0);
  EXPECT_EQ(pieces[1].cylinder, 1);
  EXPECT_EQ(pieces[2].cylinder, -1);
  EXPECT_EQ(pieces[3].cylinder, 2);
}

TEST(TubeGraph, ABranchIsAsLongAsItsCylindersJointsAndLinks) {
  const std::vector<double> tee = BranchLengths(TeeTube());
  ASSERT_EQ(tee.size(), 3u);
  EXPECT_NEAR(tee[0], 0.10, 1e-12);
  EXPECT_NEAR(tee[1], 0.10, 1e-12);
  EXPECT_NEAR(tee[2], 0.03 + 0.10, 1e-12);  // the link from the node, then the cylinder
  const std::vector<double> linear = BranchLengths(LinearTube());
  ASSERT_EQ(linear.size(), 1u);
  EXPECT_NEAR(linear[0], LinearTube().length(), 1e-12);
}

TEST(TubeGraph, ValidationNamesTheBadField) {
  Tube t = TeeTube();
  t.branches[2].to_node = 7;
  EXPECT_THAT(
      [&] { ValidateTubeGraph(t, "tubes[3]"); },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("tubes[3].branches[2]: node 7 does not exist")));
  t = TeeTube();
  t.branches[1].first_cylinder = 2;
  EXPECT_THAT([&] { ValidateTubeGraph(t, "t"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("first_cylinder = 2, expected 1")));
  t = TeeTube();
  t.branches.pop_back();
  t.nodes.pop_back();
  EXPECT_THAT([&] { ValidateTubeGraph(t, "t"); }, ::testing::ThrowsMessage<InvalidArgument>(HasSubstr(
                                                      "the branches cover 2 cylinders but the tube has 3")));
  t = TeeTube();
  t.nodes.push_back(TubeNode{});
  EXPECT_THAT([&] { ValidateTubeGraph(t, "t"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("t.nodes[4]: no branch uses it")));
  t = LinearTube();
  t.nodes.push_back(TubeNode{});
  EXPECT_THAT([&] { ValidateTubeGraph(t, "t"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("1 nodes but no branches")));
}

TEST(TubeGraph, ValidationRefusesATubeThatIsNotOneTree) {
  // Two pieces with no branch between them (node 3 hangs on a loop of its own).
  Tube t = TeeTube();
  t.branches[1] = TubeBranch{1, 0, 1, 1};
  t.branches[2] = TubeBranch{2, 3, 2, 1};
  EXPECT_THAT([&] { ValidateTubeGraph(t, "tubes[1]"); },
              ::testing::ThrowsMessage<InvalidArgument>(
                  HasSubstr("tubes[1]: nodes 0 and 2 are not joined by any path of branches")));
  // A cycle: the branch's end linked back to the trunk's end by a fourth branch.
  t = TeeTube();
  t.cylinders.push_back(Cyl({0.10, 0.13, kR}, {0.20, 0, kR}, 2));
  t.branches.push_back(TubeBranch{3, 2, 3, 1});
  EXPECT_THAT(
      [&] { ValidateTubeGraph(t, "t"); },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("t: has 4 branches for 4 nodes, so a cycle")));
  EXPECT_NO_THROW(ValidateTubeGraph(TeeTube(), "t"));
}

}  // namespace
}  // namespace tubepick
