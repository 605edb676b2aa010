#include "core/modeling/junction_joining.h"

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/common/tube_graph.h"
#include "core/modeling/end_room.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
constexpr double kR = 0.0125;
constexpr double kPi = 3.14159265358979323846;

Cylinder Cyl(const Eigen::Vector3d& a, const Eigen::Vector3d& b, std::uint32_t segment) {
  Cylinder c;
  c.start = a;
  c.end = b;
  c.radius = kR;
  c.segment_id = segment;
  return c;
}

Tube Chain(std::vector<Cylinder> cylinders) {
  Tube t;
  t.cylinders = std::move(cylinders);
  return t;
}

Eigen::Vector3d Dir(double degrees) {
  return Eigen::Vector3d(std::cos(degrees * kPi / 180.0), std::sin(degrees * kPi / 180.0), 0.0);
}

// Three arms of a Y-piece at `node`, 120° apart, each starting `gap` from the node (region
// growing leaves the junction blob out), lengths 0.30, 0.10, 0.10 as set C's first node.
std::vector<Tube> YPiece(const Eigen::Vector3d& node, double gap, std::uint32_t first_segment) {
  std::vector<Tube> arms;
  const double lengths[3] = {0.30, 0.10, 0.10};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d d = Dir(90.0 + 120.0 * k);
    arms.push_back(Chain({Cyl(node + gap * d, node + (gap + lengths[k]) * d, first_segment + k)}));
  }
  return arms;
}

TEST(JunctionJoining, ThreeArmsMeetingAtAPointBecomeOneTreeWithAYNode) {
  const Eigen::Vector3d node(0.05, -0.02, kR);
  const JunctionJoining joined = JoinJunctions(YPiece(node, 0.025, 0), JunctionParams{});
  ASSERT_EQ(joined.tubes.size(), 1u);
  EXPECT_EQ(joined.junctions, 1u);
  EXPECT_EQ(joined.y_pieces, 1u);
  const Tube& t = joined.tubes[0];
  EXPECT_NO_THROW(ValidateTubeGraph(t, "tube"));
  ASSERT_EQ(t.branches.size(), 3u);
  const std::vector<std::uint32_t> degree = NodeDegrees(t);
  ASSERT_EQ(std::count(degree.begin(), degree.end(), 3u), 1);
  EXPECT_EQ(std::count(degree.begin(), degree.end(), 1u), 3);
  const std::size_t junction = std::find(degree.begin(), degree.end(), 3u) - degree.begin();
  EXPECT_LT((t.nodes[junction].p_Bin - node).norm(), 1e-9);  // the arms' axes cross exactly there
  EXPECT_NEAR(t.length(), 0.50 + 3 * 0.025, 1e-9);
  EXPECT_EQ(joined.tube_of_chain, (std::vector<std::uint32_t>{0, 0, 0}));
}

TEST(JunctionJoining, AnEndPointingAtAnotherTubesSideSplitsItIntoATee) {
  // A run along x, cylinders of 0.10 and 0.20; a branch along y ending 3 cm from its axis at x = 0.16.
  std::vector<Tube> chains = {
      Chain({Cyl({0, 0, kR}, {0.10, 0, kR}, 0), Cyl({0.10, 0, kR}, {0.30, 0, kR}, 1)}),
      Chain({Cyl({0.16, 0.13, kR}, {0.16, 0.03, kR}, 2)})};
  const JunctionJoining joined = JoinJunctions(chains, JunctionParams{});
  ASSERT_EQ(joined.tubes.size(), 1u);
  EXPECT_EQ(joined.y_pieces, 0u);
  const Tube& t = joined.tubes[0];
  EXPECT_NO_THROW(ValidateTubeGraph(t, "tube"));
  ASSERT_EQ(t.cylinders.size(), 4u);  // the 0.20 cylinder is cut at the junction's foot
  ASSERT_EQ(t.branches.size(), 3u);
  const std::vector<std::uint32_t> degree = NodeDegrees(t);
  const std::size_t junction = std::find(degree.begin(), degree.end(), 3u) - degree.begin();
  ASSERT_LT(junction, degree.size());
  EXPECT_TRUE(t.nodes[junction].p_Bin.isApprox(Eigen::Vector3d(0.16, 0, kR), 1e-9));
  // The cut keeps the run's axis and segment: pieces of 0.06 and 0.14.
  std::vector<double> lengths;
  for (const Cylinder& c : t.cylinders) lengths.push_back(c.length());
  std::sort(lengths.begin(), lengths.end());
  EXPECT_NEAR(lengths[0], 0.06, 1e-9);
  EXPECT_NEAR(lengths[3], 0.14, 1e-9);
  EXPECT_NEAR(t.length(), 0.30 + 0.03 + 0.10, 1e-9);
}

TEST(JunctionJoining, TwoTeesWithNoCylinderBetweenThemShareTheirNode) {
  // A run broken by a 5 cm joint (x from -0.02 to 0.03); two branches, from either side, point
  // at the joint 2.5 cm apart (beyond node_spacing): no cylinder lies between their feet, so no
  // branch can link two nodes there. Found on a generated set-C bin, where the tree came out in
  // two pieces with no branch between them.
  const std::vector<Tube> chains = {
      Chain({Cyl({-0.20, 0, kR}, {-0.02, 0, kR}, 0), Cyl({0.03, 0, kR}, {0.20, 0, kR}, 1)}),
      Chain({Cyl({-0.005, 0.15, kR}, {-0.005, 0.03, kR}, 2)}),
      Chain({Cyl({0.02, -0.15, kR}, {0.02, -0.03, kR}, 3)})};
  const JunctionJoining joined = JoinJunctions(chains, JunctionParams{});
  ASSERT_EQ(joined.tubes.size(), 1u);
  EXPECT_EQ(joined.junctions, 2u);
  const Tube& t = joined.tubes[0];
  EXPECT_NO_THROW(ValidateTubeGraph(t, "tube"));  // one tree: every node joined to every other
  const std::vector<std::uint32_t> degree = NodeDegrees(t);
  EXPECT_EQ(std::count(degree.begin(), degree.end(), 4u), 1);  // one node, four arms
  EXPECT_EQ(t.cylinders.size(), 4u);
}

TEST(JunctionJoining, ATubeLyingAcrossAnotherIsNoJunction) {
  // The second tube's end is 3 cm from the first's side but its axis passes two radii above.
  std::vector<Tube> chains = {Chain({Cyl({0, 0, kR}, {0.30, 0, kR}, 0)}),
                              Chain({Cyl({0.16, 0.13, 3 * kR}, {0.16, 0.03, 3 * kR}, 1)})};
  EXPECT_EQ(JoinJunctions(chains, JunctionParams{}).tubes.size(), 2u);
  // And an end that points along the other tube (15° off it) is the linear joining's business.
  chains[1] = Chain({Cyl(Eigen::Vector3d(0.16, 0, kR) + 0.13 * Dir(165),
                         Eigen::Vector3d(0.16, 0, kR) + 0.03 * Dir(165), 1)});
  EXPECT_EQ(JoinJunctions(chains, JunctionParams{}).tubes.size(), 2u);
}

TEST(JunctionJoining, LimitsKeepTreesAndSizes) {
  // Two Y-pieces sharing the long arm would close no cycle; but the tube would be 1.1 m.
  std::vector<Tube> chains = YPiece({0, 0, kR}, 0.025, 0);
  JunctionParams params;
  params.max_tube_length = 0.5;  // the Y is 0.575 m with its links
  EXPECT_EQ(JoinJunctions(chains, params).tubes.size(), 3u);
  params = JunctionParams{};
  chains.pop_back();  // two ends meeting alone (a 60° kink) are linked end to end: one linear tube
  const JunctionJoining linked = JoinJunctions(chains, params);
  ASSERT_EQ(linked.tubes.size(), 1u);
  EXPECT_FALSE(linked.tubes[0].branched());
  EXPECT_EQ(BranchesOf(linked.tubes[0]).size(), 1u);  // no pass-through node is left
  EXPECT_NEAR(linked.tubes[0].length(), 0.40 + 2 * 0.025 * std::sin(kPi / 3.0), 1e-9);
  params.link_max_angle = 0.5;  // the kink is 60°: beyond this limit nothing joins them
  EXPECT_EQ(JoinJunctions(chains, params).tubes.size(), 2u);
  params.max_branches_per_node = 2;
  EXPECT_THAT(
      [&] { JoinJunctions(chains, params); },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("modeling.junctions.max_branches_per_node: 2")));
}

TEST(JunctionJoining, TheCellsTubeLengthBoundsEveryTree) {
  // The Y is 0.575 m with its links: within 1.04 × 0.56 m (0.582), not within 1.04 × 0.55 m (0.572).
  const std::vector<Tube> chains = YPiece({0, 0, kR}, 0.025, 0);
  const JunctionParams params;
  EXPECT_EQ(JoinJunctions(chains, params, JunctionShape::kAny, nullptr, {}, 0.56).tubes.size(), 1u);
  // Refused, the Y leaves three ends; the completion then links two arms within 0.55 m.
  const JunctionJoining refused = JoinJunctions(chains, params, JunctionShape::kAny, nullptr, {}, 0.55);
  EXPECT_EQ(refused.tubes.size(), 2u);
  EXPECT_EQ(refused.y_pieces, 0u);
  EXPECT_EQ(refused.completions, 1u);
  EXPECT_EQ(JoinJunctions(chains, params, JunctionShape::kAny, nullptr, {}, 0.0).tubes.size(),
            1u);  // unknown
  JunctionParams wider = params;
  wider.max_length_share = 1.05;  // 0.5775
  EXPECT_EQ(JoinJunctions(chains, wider, JunctionShape::kAny, nullptr, {}, 0.55).tubes.size(), 1u);
  wider.max_tube_length = 0.57;  // the absolute limit still holds
  EXPECT_EQ(JoinJunctions(chains, wider, JunctionShape::kAny, nullptr, {}, 0.55).y_pieces, 0u);
  wider.max_length_share = 0.0;
  EXPECT_THAT([&] { JoinJunctions(chains, wider); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("modeling.junctions.max_length_share")));
}

// `count` Y-pieces of 0.575 m (with their links) side by side, 0.4 m apart.
std::vector<Tube> YPieces(int count) {
  std::vector<Tube> chains;
  for (int i = 0; i < count; ++i) {
    for (Tube& arm : YPiece({-0.6 + 0.4 * i, 0, kR}, 0.025, 3 * static_cast<std::uint32_t>(i))) {
      chains.push_back(std::move(arm));
    }
  }
  return chains;
}

TEST(JunctionJoining, ATubeLengthShorterThanFourWholeTreesShowIsNotBelieved) {
  const JunctionParams params;
  std::optional<double> disagrees = 1.0;
  // The cell's length right: four trees, as JoinJunctions makes them.
  EXPECT_EQ(JoinJunctionsOfLength(YPieces(4), params, JunctionShape::kAny, nullptr, {}, 0.575, &disagrees)
                .tubes.size(),
            4u);
  EXPECT_FALSE(disagrees.has_value());
  // Said to be 0.50 m: bound by it, every Y would be refused (0.575 > 0.52 m). The four trees the
  // scan shows whole are 0.575 m (median), so they are joined as that long, and it is said.
  ASSERT_GT(JoinJunctions(YPieces(4), params, JunctionShape::kAny, nullptr, {}, 0.50).tubes.size(), 4u);
  EXPECT_EQ(JoinJunctionsOfLength(YPieces(4), params, JunctionShape::kAny, nullptr, {}, 0.50, &disagrees)
                .tubes.size(),
            4u);
  ASSERT_TRUE(disagrees.has_value());
  EXPECT_NEAR(*disagrees, 0.575, 0.01);
  // Three trees are too few to overrule the cell (in a bin of three, one merge can be the median).
  const JunctionJoining three =
      JoinJunctionsOfLength(YPieces(3), params, JunctionShape::kAny, nullptr, {}, 0.50, &disagrees);
  EXPECT_FALSE(disagrees.has_value());
  EXPECT_EQ(three.tubes.size(),
            JoinJunctions(YPieces(3), params, JunctionShape::kAny, nullptr, {}, 0.50).tubes.size());
  EXPECT_GT(three.tubes.size(), 3u);
}

TEST(JunctionJoining, TheRoomPastAnEndSetsItsReach) {
  // A run along x; a branch along y whose cylinder ends 8 cm from the run's axis (region growing
  // left its last centimetres unfitted): beyond the T-piece reach (radius + side_max_gap).
  const Eigen::Vector3d foot(0.16, 0, kR);
  const std::vector<Tube> chains = {Chain({Cyl({0, 0, kR}, {0.30, 0, kR}, 0)}),
                                    Chain({Cyl(foot + 0.18 * Dir(90), foot + 0.08 * Dir(90), 1)})};
  EXPECT_EQ(JoinJunctions(chains, JunctionParams{}).tubes.size(), 2u);
  // 4 cm of unfitted surface past the branch's end make the junction.
  EndRooms rooms(2);
  rooms[1][1].unfitted = 0.04;
  const JunctionJoining joined = JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny, nullptr, rooms);
  ASSERT_EQ(joined.tubes.size(), 1u);
  EXPECT_TRUE(joined.tubes[0].branched());
  // Where the scanner saw past the branch's axis 5 cm out, it does not reach the run.
  rooms[1][1].free = 0.05;
  EXPECT_EQ(JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny, nullptr, rooms).tubes.size(), 2u);
  // Free space 1 cm out refuses even a branch ending 3 cm from the run, nominally within reach
  // (the shortened axis must still come within side_max_axis_offset of the run's).
  const std::vector<Tube> near = {chains[0], Chain({Cyl(foot + 0.13 * Dir(90), foot + 0.03 * Dir(90), 1)})};
  EXPECT_EQ(JoinJunctions(near, JunctionParams{}).tubes.size(), 1u);
  EndRooms seen_through(2);
  seen_through[1][1].free = 0.01;
  EXPECT_EQ(JoinJunctions(near, JunctionParams{}, JunctionShape::kAny, nullptr, seen_through).tubes.size(),
            2u);
  EXPECT_DOUBLE_EQ(ReachOf(EndRoom{0.04, 0.2}, 0.05), 0.09);
  EXPECT_DOUBLE_EQ(ReachOf(EndRoom{0.04, 0.07}, 0.05), 0.07);
}

TEST(JunctionJoining, EndsLeftOverAreCompletedWithinTheTubeLength) {
  // A 30 cm run along x; a 10 cm branch along y ending 7 cm from the run's axis: past the T-piece
  // reach (radius + side_max_gap, 5.25 cm), within the completion's (radius + 8 cm).
  const Eigen::Vector3d foot(0.16, 0, kR);
  const std::vector<Tube> chains = {Chain({Cyl({0, 0, kR}, {0.30, 0, kR}, 0)}),
                                    Chain({Cyl(foot + 0.17 * Dir(90), foot + 0.07 * Dir(90), 1)})};
  const JunctionParams params;
  auto join = [&](const std::vector<Tube>& c, double tube_length,
                  const JunctionParams& p = JunctionParams{}) {
    return JoinJunctions(c, p, JunctionShape::kAny, nullptr, {}, tube_length);
  };
  EXPECT_EQ(join(chains, 0.0).tubes.size(), 2u);  // the tube length unknown: no completion
  const JunctionJoining completed = join(chains, 0.75);
  ASSERT_EQ(completed.tubes.size(), 1u);
  EXPECT_TRUE(completed.tubes[0].branched());
  EXPECT_EQ(completed.completions, 1u);
  EXPECT_EQ(completed.junctions, 0u);  // never counted towards a branched-looking scene
  EXPECT_FALSE(LooksBranched(completed, params));
  // The tree would be 0.30 + 0.10 + 0.07 m: not within a tube of 0.45 m.
  EXPECT_EQ(join(chains, 0.45).tubes.size(), 2u);
  EXPECT_EQ(join(chains, 0.48).tubes.size(), 1u);
  JunctionParams off = params;
  off.completion.enabled = false;
  EXPECT_EQ(join(chains, 0.75, off).tubes.size(), 2u);
  // An axis passing 1.8 cm above the run's (a bent branch fitted straight): past the T-piece's
  // 1.6 cm, within the completion's 2 cm; 2.4 cm is past both.
  auto lifted = [&](double dz) {
    const Eigen::Vector3d up(0, 0, dz);
    return std::vector<Tube>{chains[0],
                             Chain({Cyl(foot + up + 0.13 * Dir(90), foot + up + 0.03 * Dir(90), 1)})};
  };
  EXPECT_EQ(join(lifted(0.018), 0.0).tubes.size(), 2u);
  EXPECT_EQ(join(lifted(0.018), 0.75).tubes.size(), 1u);
  EXPECT_EQ(join(lifted(0.024), 0.75).tubes.size(), 2u);
  off.completion.enabled = true;
  off.completion.max_axis_offset = 0.0;
  EXPECT_THAT(
      [&] { join(chains, 0.75, off); },
      ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("modeling.junctions.completion.max_axis_offset")));
}

TEST(JunctionJoining, TwoArmsOfAYWhoseThirdIsHiddenAreLinkedAcrossAWideKink) {
  // Two arms 50° apart leave a node 2.5 cm from their ends (a kink of 130°); the third arm is
  // hidden. Their axes meet, so they are one tube; the thesis-like 90° limit would leave two.
  const Eigen::Vector3d node(0, 0, kR);
  const std::vector<Tube> chains = {Chain({Cyl(node + 0.30 * Dir(180), node + 0.025 * Dir(180), 0)}),
                                    Chain({Cyl(node + 0.025 * Dir(130), node + 0.15 * Dir(130), 1)})};
  ASSERT_EQ(JoinJunctions(chains, JunctionParams{}).tubes.size(), 1u);
  JunctionParams params;
  params.link_max_angle = kPi / 2.0;
  EXPECT_EQ(JoinJunctions(chains, params).tubes.size(), 2u);
}

TEST(JunctionJoining, TheThirdArmOfALinkedPairJoinsTheirNodeInTheCompletion) {
  // Two arms linked across a 130° kink at `node` (as above) and a third arm whose end lies 9 cm
  // from the node, pointing at it: past a Y-piece's reach (radius + 5 cm), within the
  // completion's (radius + 10 cm). The completion pairs it with an end the link already took.
  const Eigen::Vector3d node(0, 0, kR);
  const std::vector<Tube> chains = {Chain({Cyl(node + 0.30 * Dir(180), node + 0.025 * Dir(180), 0)}),
                                    Chain({Cyl(node + 0.025 * Dir(130), node + 0.15 * Dir(130), 1)}),
                                    Chain({Cyl(node + 0.19 * Dir(280), node + 0.09 * Dir(280), 2)})};
  auto join = [&](double tube_length) {
    return JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny, nullptr, {}, tube_length);
  };
  EXPECT_EQ(join(0.0).tubes.size(), 2u);  // no completion without the tube length
  const JunctionJoining joined = join(0.75);
  ASSERT_EQ(joined.tubes.size(), 1u);
  const std::vector<std::uint32_t> degree = NodeDegrees(joined.tubes[0]);
  EXPECT_EQ(std::count(degree.begin(), degree.end(), 3u), 1);  // the link's node is a Y now
  EXPECT_LT((joined.tubes[0].nodes[std::find(degree.begin(), degree.end(), 3u) - degree.begin()].p_Bin - node)
                .norm(),
            0.01);
  ASSERT_EQ(joined.decisions.size(), 2u);
  EXPECT_EQ(joined.decisions[0].kind, JoinDecision::Kind::kLink);
  EXPECT_EQ(joined.decisions[1].kind, JoinDecision::Kind::kCompletionNode);
  EXPECT_EQ(joined.decisions[1].chains, (std::vector<std::uint32_t>{2, 0}));
  EXPECT_EQ(joined.completions, 1u);
  EXPECT_EQ(joined.y_pieces, 0u);  // a completion never makes a scene look branched
  EXPECT_EQ(joined.junctions, 0u);
  // Within the tube length only: 0.275 + 0.125 + 0.10 + the links (0.025 + 0.025 + 0.09), 0.64 m.
  EXPECT_EQ(join(0.62).tubes.size(), 2u);
  EXPECT_EQ(join(0.66).tubes.size(), 1u);
}

TEST(JunctionJoining, TwoEndsFacingAcrossAHiddenGapAreJudgedFromBothEnds) {
  // A run ends at the origin pointing along x; the other part of it goes on 9.5 cm further and
  // 2.4 cm aside (a bend under the tube that hides the gap), its end pointing straight back at the
  // run's end. From the run's axis the other end is 2.4 cm off, past the completion's 2 cm; from
  // its own axis 0: the mean, 1.2 cm, is within, whichever chain comes first.
  const Eigen::Vector3d p_x(0, 0, kR), p_y(0.095, 0.024, kR);
  const Eigen::Vector3d u = (p_x - p_y).normalized();
  const Tube run = Chain({Cyl(p_x - 0.25 * Eigen::Vector3d::UnitX(), p_x, 0)});
  const Tube other = Chain({Cyl(p_y - 0.15 * u, p_y, 1)});
  auto join = [&](const std::vector<Tube>& chains, bool mean) {
    JunctionParams params;
    params.completion.facing_offset_mean = mean;
    return JoinJunctions(chains, params, JunctionShape::kAny, nullptr, {}, 0.75);
  };
  for (const auto& chains : {std::vector<Tube>{run, other}, std::vector<Tube>{other, run}}) {
    const JunctionJoining joined = join(chains, true);
    ASSERT_EQ(joined.tubes.size(), 1u);
    ASSERT_EQ(joined.decisions.size(), 1u);
    EXPECT_EQ(joined.decisions[0].kind, JoinDecision::Kind::kCompletionLink);
    EXPECT_NEAR(joined.tubes[0].length(), 0.25 + (p_y - p_x).norm() + 0.15, 1e-9);
  }
  // Judged from the first chain's axis only, the order decides.
  EXPECT_EQ(join({run, other}, false).tubes.size(), 2u);
  EXPECT_EQ(join({other, run}, false).tubes.size(), 1u);
  // The completion's reach is the radius plus 10 cm from each end: a straight gap of 20 cm is
  // bridged (not with 8 cm), one of 24 cm is not.
  auto beyond = [&](double gap) {
    const Eigen::Vector3d p = p_x + gap * Eigen::Vector3d::UnitX();
    return Chain({Cyl(p + 0.15 * Eigen::Vector3d::UnitX(), p, 1)});
  };
  EXPECT_EQ(join({run, beyond(0.20)}, true).tubes.size(), 1u);
  EXPECT_EQ(join({run, beyond(0.24)}, true).tubes.size(), 2u);
  JunctionParams shorter;
  shorter.completion.max_gap = 0.08;
  EXPECT_EQ(JoinJunctions({run, beyond(0.20)}, shorter, JunctionShape::kAny, nullptr, {}, 0.75).tubes.size(),
            2u);
}

TEST(JunctionJoining, ASecondBranchJoinsATeeNodeInTheCompletion) {
  // A T-piece: a run along x, a branch along y ending 3 cm from the run's axis at x = 0.16. A third
  // chain comes in along the run from +x, 1.8 cm above its axis, its end 5 cm short of the node:
  // parallel to the run, it is no T-piece of it, but its axis meets the branch's within the
  // completion's 2 cm (not the 1.6 cm of a link).
  const Eigen::Vector3d foot(0.16, 0, kR);
  const Eigen::Vector3d above(0, 0, 0.018);
  const std::vector<Tube> chains = {
      Chain({Cyl({0, 0, kR}, {0.30, 0, kR}, 0)}),
      Chain({Cyl(foot + 0.13 * Dir(90), foot + 0.03 * Dir(90), 1)}),
      Chain({Cyl(foot + above + 0.20 * Dir(0), foot + above + 0.05 * Dir(0), 2)})};
  const JunctionJoining joined =
      JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny, nullptr, {}, 0.75);
  ASSERT_EQ(joined.tubes.size(), 1u);
  const std::vector<std::uint32_t> degree = NodeDegrees(joined.tubes[0]);
  EXPECT_EQ(std::count(degree.begin(), degree.end(), 4u), 1);  // the T-node takes a fourth branch
  ASSERT_EQ(joined.decisions.size(), 2u);
  EXPECT_EQ(joined.decisions[0].kind, JoinDecision::Kind::kTPiece);
  EXPECT_EQ(joined.decisions[1].kind, JoinDecision::Kind::kCompletionNode);
  EXPECT_EQ(joined.decisions[1].chains, (std::vector<std::uint32_t>{2, 1}));
  EXPECT_EQ(joined.junctions, 1u);
  // A junction shape allows three branches at a node.
  EXPECT_EQ(JoinJunctions(chains, JunctionParams{}, JunctionShape::kTee, nullptr, {}, 0.75).tubes.size(), 2u);
}

// A run along x with a branch at `branch_degrees` from it, ending 3 cm from the run's axis.
std::vector<Tube> BranchOffARun(double branch_degrees) {
  const Eigen::Vector3d foot(0.16, 0, kR);
  return {Chain({Cyl({0, 0, kR}, {0.10, 0, kR}, 0), Cyl({0.10, 0, kR}, {0.30, 0, kR}, 1)}),
          Chain({Cyl(foot + 0.13 * Dir(branch_degrees), foot + 0.03 * Dir(branch_degrees), 2)})};
}

TEST(JunctionJoining, AJunctionShapeAcceptsOnlyJunctionsWhoseArmsFitIt) {
  const std::vector<Tube> wye = YPiece({0.05, -0.02, kR}, 0.025, 0);
  const std::vector<Tube> tee = BranchOffARun(90.0);
  const JunctionParams params;
  EXPECT_EQ(JoinJunctions(wye, params, JunctionShape::kWye).tubes.size(), 1u);
  EXPECT_EQ(JoinJunctions(tee, params, JunctionShape::kTee).tubes.size(), 1u);
  EXPECT_EQ(JoinJunctions(tee, params, JunctionShape::kAny).tubes.size(), 1u);
  // A tee's arms are 90°, 90° and 180° apart: 60° from a wye's 120°, beyond the 55° tolerance.
  EXPECT_EQ(JoinJunctions(tee, params, JunctionShape::kWye).tubes.size(), 2u);
  EXPECT_EQ(JoinJunctions(wye, params, JunctionShape::kTee).tubes.size(), 3u);
  // A branch at 60° to the run (arms 60°, 120°, 180°): 60° off a wye's, 30° off a tee's.
  EXPECT_EQ(JoinJunctions(BranchOffARun(60.0), params, JunctionShape::kWye).tubes.size(), 2u);
  EXPECT_EQ(JoinJunctions(BranchOffARun(60.0), params, JunctionShape::kTee).tubes.size(), 1u);
  JunctionParams strict;
  strict.shape_tolerance = 20.0 * kPi / 180.0;
  EXPECT_EQ(JoinJunctions(BranchOffARun(60.0), strict, JunctionShape::kTee).tubes.size(), 2u);
  EXPECT_EQ(JoinJunctions(BranchOffARun(80.0), strict, JunctionShape::kTee).tubes.size(), 1u);
}

TEST(JunctionJoining, AWyeTakesTheThreeEndsThatFitItAndLeavesAChanceFourth) {
  const Eigen::Vector3d node(0.05, -0.02, kR);
  std::vector<Tube> chains = YPiece(node, 0.025, 0);
  // A fourth tube's end meets the node too, 35° from one arm.
  const Eigen::Vector3d d = Dir(90.0 + 35.0);
  chains.push_back(Chain({Cyl(node + 0.20 * d, node + 0.025 * d, 3)}));
  // Any shape: which three of the four belong together cannot be told, so no node is made ...
  const JunctionJoining any = JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny);
  EXPECT_EQ(any.y_pieces, 0u);
  EXPECT_EQ(any.tubes.size(), 4u);
  // ... unless the cell expects X-pieces: a node of four branches.
  JunctionParams crosses;
  crosses.max_meeting_ends = 4;
  const JunctionJoining x = JoinJunctions(chains, crosses, JunctionShape::kAny);
  ASSERT_EQ(x.tubes.size(), 1u);
  EXPECT_EQ(x.y_pieces, 1u);
  crosses.max_meeting_ends = 5;  // more than max_branches_per_node gathers
  EXPECT_THAT([&] { JoinJunctions(chains, crosses); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("modeling.junctions.max_meeting_ends: 5")));
  const JunctionJoining wye = JoinJunctions(chains, JunctionParams{}, JunctionShape::kWye);
  ASSERT_EQ(wye.tubes.size(), 2u);
  EXPECT_EQ(wye.y_pieces, 1u);
  EXPECT_EQ(wye.tubes[1].cylinders.size(), 1u);
  EXPECT_EQ(wye.tubes[1].cylinders[0].segment_id, 3u);
}

TEST(JunctionJoining, ARunFittedThroughTheBendOfAWyeShowsTheBend) {
  // The run's two cylinders meet at the node, 120° apart (the chain joining went through the
  // bend); the third arm ends 3 cm from the node. The run's arms are measured 3 cm from the node.
  const Eigen::Vector3d node(0.10, 0.05, kR);
  std::vector<Tube> chains = {
      Chain({Cyl(node + 0.10 * Dir(210), node, 0), Cyl(node, node + 0.10 * Dir(-30), 1)}),
      Chain({Cyl(node + 0.13 * Dir(90), node + 0.03 * Dir(90), 2)})};
  const JunctionJoining joined = JoinJunctions(chains, JunctionParams{}, JunctionShape::kWye);
  ASSERT_EQ(joined.tubes.size(), 1u);
  EXPECT_TRUE(joined.tubes[0].branched());
  EXPECT_EQ(JoinJunctions(chains, JunctionParams{}, JunctionShape::kTee).tubes.size(), 2u);
}

TEST(JunctionJoining, ShapeToleranceIsValidated) {
  JunctionParams params;
  params.shape_tolerance = -0.1;
  EXPECT_THAT([&] { params.Validate(); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("modeling.junctions.shape_tolerance")));
}

TEST(JunctionJoining, AutoTopologyNeedsSeveralJunctionsOrYPieces) {
  JunctionParams params;
  JunctionJoining joined;
  joined.tubes.resize(10);
  joined.junctions = 2;
  EXPECT_FALSE(LooksBranched(joined, params));  // below auto_min_junctions
  joined.junctions = 6;
  EXPECT_FALSE(LooksBranched(joined, params));  // 0.6 per tube
  joined.junctions = 7;
  EXPECT_TRUE(LooksBranched(joined, params));
  joined.junctions = 3;
  joined.y_pieces = 3;
  EXPECT_TRUE(LooksBranched(joined, params));
}

// A tree of set C's layout: junctions at (0, 0) and (spacing, 0) joined by a straight run, two
// branches of 0.10 at the first and branches of 0.10 and `long_branch` at the second.
Tube TwoJunctionTree(double spacing, double long_branch) {
  Tube t;
  const Eigen::Vector3d a(0, 0, kR), b(spacing, 0, kR);
  t.nodes = {TubeNode{a},
             TubeNode{b},
             TubeNode{a + 0.10 * Dir(135)},
             TubeNode{a + 0.10 * Dir(225)},
             TubeNode{b + 0.10 * Dir(45)},
             TubeNode{b + long_branch * Dir(-45)}};
  t.cylinders = {Cyl(a, b, 0), Cyl(a, t.nodes[2].p_Bin, 1), Cyl(a, t.nodes[3].p_Bin, 2),
                 Cyl(b, t.nodes[4].p_Bin, 3), Cyl(b, t.nodes[5].p_Bin, 4)};
  t.branches = {TubeBranch{0, 1, 0, 1}, TubeBranch{0, 2, 1, 1}, TubeBranch{0, 3, 2, 1},
                TubeBranch{1, 4, 3, 1}, TubeBranch{1, 5, 4, 1}};
  return t;
}

TEST(JunctionJoining, ATreeFitsTheJunctionLayoutOfItsPart) {
  const JunctionLayout set_c{2, 0.30, 0.15};
  EXPECT_TRUE(FitsJunctionLayout(TwoJunctionTree(0.30, 0.15), set_c, 0.04));
  EXPECT_TRUE(FitsJunctionLayout(TwoJunctionTree(0.33, 0.15), set_c, 0.04));
  // Two junctions a run of 0.20 apart: one of them is a stranger's.
  EXPECT_FALSE(FitsJunctionLayout(TwoJunctionTree(0.20, 0.15), set_c, 0.04));
  EXPECT_TRUE(FitsJunctionLayout(TwoJunctionTree(0.20, 0.15), JunctionLayout{2, 0.0, 0.15}, 0.04));
  // A branch of 0.25 hides a third junction the part does not have.
  EXPECT_FALSE(FitsJunctionLayout(TwoJunctionTree(0.30, 0.25), set_c, 0.04));
  EXPECT_TRUE(FitsJunctionLayout(TwoJunctionTree(0.30, 0.25), JunctionLayout{2, 0.30, 0.0}, 0.04));
  EXPECT_TRUE(FitsJunctionLayout(TwoJunctionTree(0.30, 0.25), JunctionLayout{3, 0.30, 0.15}, 0.04));
  // One junction: the trunk may go on through the other, hidden one; two long arms may not.
  const std::vector<Tube> y = YPiece({0, 0, kR}, 0.0, 0);
  const JunctionJoining one = JoinJunctions(y, JunctionParams{});
  ASSERT_EQ(one.tubes.size(), 1u);
  EXPECT_TRUE(FitsJunctionLayout(one.tubes[0], set_c, 0.04));
  std::vector<Tube> long_arms = y;
  long_arms[1].cylinders[0].end = 0.25 * Dir(210) + Eigen::Vector3d(0, 0, kR);
  const JunctionJoining two_long = JoinJunctions(long_arms, JunctionParams{});
  ASSERT_EQ(two_long.tubes.size(), 1u);
  EXPECT_FALSE(FitsJunctionLayout(two_long.tubes[0], set_c, 0.04));
  EXPECT_TRUE(FitsJunctionLayout(Chain({Cyl({0, 0, kR}, {0.7, 0, kR}, 0)}), set_c, 0.04));
}

TEST(JunctionJoining, AWyeIsCheckedAgainstTheLayoutWhenItLeavesOutTheMeetingsFirstEnd) {
  // A Y-piece with arms of 0.30, 0.25 and 0.10 (two long arms: three junctions for a part of two)
  // and, first among the chains, a chance fourth end that meets the node cheapest of all.
  const Eigen::Vector3d node(0.05, -0.02, kR);
  std::vector<Tube> arms = YPiece(node, 0.025, 1);
  arms[1].cylinders[0].end = node + 0.275 * Dir(210);
  const Eigen::Vector3d d = Dir(90.0 + 35.0);
  std::vector<Tube> chains = {Chain({Cyl(node + 0.20 * d, node + 0.015 * d, 0)})};
  chains.insert(chains.end(), arms.begin(), arms.end());
  ASSERT_EQ(JoinJunctions(chains, JunctionParams{}, JunctionShape::kWye).y_pieces, 1u);
  const JunctionJoining drawn = JoinJunctions(chains, JunctionParams{}, JunctionShape::kWye, nullptr, {}, 0.0,
                                              JunctionLayout{2, 0.30, 0.15});
  EXPECT_EQ(drawn.y_pieces, 0u);
  EXPECT_EQ(drawn.tubes.size(), 4u);
}

TEST(JunctionJoining, AStrangersEndOnTheTrunkIsNoJunctionWhereThePartHasNone) {
  // A Y-piece (arms 0.30 up, 0.10, 0.10) and a stranger's end 3 cm from the trunk's side, 0.12 m
  // up it: a T-piece by its geometry, but set C's two junctions are 0.30 m apart.
  std::vector<Tube> chains = YPiece({0, 0, kR}, 0.025, 0);
  chains.push_back(Chain({Cyl({0.13, 0.12, kR}, {0.03, 0.12, kR}, 3)}));
  const JunctionJoining blind = JoinJunctions(chains, JunctionParams{});
  ASSERT_EQ(blind.tubes.size(), 1u);
  EXPECT_EQ(blind.junctions, 2u);
  const JunctionJoining drawn = JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny, nullptr, {}, 0.0,
                                              JunctionLayout{2, 0.30, 0.15});
  ASSERT_EQ(drawn.tubes.size(), 2u);
  EXPECT_EQ(drawn.junctions, 1u);
  EXPECT_EQ(drawn.tube_of_chain[0], drawn.tube_of_chain[1]);
  EXPECT_NE(drawn.tube_of_chain[3], drawn.tube_of_chain[0]);
  // At 0.30 m up the trunk it would be the part's second junction.
  chains.back() = Chain({Cyl({0.13, 0.30, kR}, {0.03, 0.30, kR}, 3)});
  EXPECT_EQ(JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny, nullptr, {}, 0.0,
                          JunctionLayout{2, 0.30, 0.15})
                .tubes.size(),
            1u);
}

TEST(JunctionJoining, EveryDecisionNamesItsKindItsChainsAndWhetherTheLayoutKeptIt) {
  // The Y-piece and the stranger's end on its trunk, as above: the T-piece is decided and kept
  // without the layout, decided and taken back with it.
  std::vector<Tube> chains = YPiece({0, 0, kR}, 0.025, 0);
  chains.push_back(Chain({Cyl({0.13, 0.12, kR}, {0.03, 0.12, kR}, 3)}));
  const JunctionJoining blind = JoinJunctions(chains, JunctionParams{});
  ASSERT_EQ(blind.decisions.size(), 2u);
  EXPECT_EQ(blind.decisions[0].kind, JoinDecision::Kind::kYPiece);
  EXPECT_TRUE(blind.decisions[0].accepted);
  EXPECT_EQ(blind.decisions[0].chains, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(blind.decisions[1].kind, JoinDecision::Kind::kTPiece);
  EXPECT_TRUE(blind.decisions[1].accepted);
  EXPECT_EQ(blind.decisions[1].chains, (std::vector<std::uint32_t>{3, 0}));  // the branch, then the trunk
  const JunctionJoining drawn = JoinJunctions(chains, JunctionParams{}, JunctionShape::kAny, nullptr, {}, 0.0,
                                              JunctionLayout{2, 0.30, 0.15});
  ASSERT_EQ(drawn.decisions.size(), 2u);
  EXPECT_TRUE(drawn.decisions[0].accepted);
  EXPECT_EQ(drawn.decisions[1].kind, JoinDecision::Kind::kTPiece);
  EXPECT_FALSE(drawn.decisions[1].accepted);
  EXPECT_EQ(drawn.decisions[1].chains, (std::vector<std::uint32_t>{3, 0}));
  EXPECT_EQ(ToString(JoinDecision::Kind::kCompletionLink), "completion_link");
}

TEST(JunctionJoining, IsDeterministicAndKeepsLinearChainsAsTheyCame) {
  std::vector<Tube> chains = YPiece({0, 0, kR}, 0.02, 0);
  const std::vector<Tube> y2 = YPiece({0.4, 0.1, kR}, 0.03, 10);
  chains.insert(chains.end(), y2.begin(), y2.end());
  chains.push_back(Chain({Cyl({-0.3, -0.25, kR}, {0.1, -0.25, kR}, 20)}));
  const JunctionJoining a = JoinJunctions(chains, JunctionParams{});
  const JunctionJoining b = JoinJunctions(chains, JunctionParams{});
  ASSERT_EQ(a.tubes.size(), 3u);
  ASSERT_EQ(b.tubes.size(), 3u);
  for (std::size_t t = 0; t < a.tubes.size(); ++t) {
    EXPECT_EQ(a.tubes[t].id, t);
    EXPECT_EQ(a.tubes[t].branches, b.tubes[t].branches);
    EXPECT_EQ(a.tubes[t].cylinders.size(), b.tubes[t].cylinders.size());
  }
  // The lone straight tube (0.40 m) is returned as it came: implicit graph, same cylinder.
  const auto lone = std::find_if(a.tubes.begin(), a.tubes.end(), [](const Tube& t) { return !t.branched(); });
  ASSERT_NE(lone, a.tubes.end());
  EXPECT_TRUE(lone->branches.empty());
  EXPECT_EQ(lone->cylinders[0].segment_id, 20u);
  EXPECT_EQ(a.tube_of_chain[6], static_cast<std::uint32_t>(lone - a.tubes.begin()));
}

}  // namespace
}  // namespace tubepick
