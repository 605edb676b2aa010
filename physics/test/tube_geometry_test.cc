#include "physics/tube_geometry.h"

#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick::physics {
namespace {

using ::testing::HasSubstr;
constexpr double kTol = 1e-12;

/// Nodes (id, centre) joined in the given order, radius 1 cm.
TubeGeometry Chain(const std::vector<std::pair<int, Eigen::Vector3d>>& points) {
  TubeGeometry tube;
  tube.id = 7;
  for (const auto& [id, p] : points) tube.nodes.push_back({id, p, 0.01});
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    TubeEdge e;
    e.node1 = points[i].first;
    e.node2 = points[i + 1].first;
    e.name = "e_" + std::to_string(e.node1) + "_" + std::to_string(e.node2);
    e.order = static_cast<int>(i) + 1;
    e.radius = 0.01;
    SetEdgeFromNodes(tube, e);
    tube.edges.push_back(e);
  }
  return tube;
}

TEST(TubeGeometry, LinearTubeHelpers) {
  const TubeGeometry tube = Chain({{1, {0, 0, 0}}, {4, {0.1, 0, 0}}, {2, {0.1, 0.2, 0}}});
  EXPECT_TRUE(tube.IsLinear());
  EXPECT_NEAR(tube.Length(), 0.3, kTol);
  EXPECT_EQ(tube.Degree(4), 2);
  EXPECT_TRUE(tube.IsJoint(4));
  EXPECT_FALSE(tube.IsJoint(1));
  const std::vector<Cylinder> cylinders = tube.Cylinders();
  ASSERT_EQ(cylinders.size(), 2u);
  EXPECT_TRUE(cylinders[1].start.isApprox(Eigen::Vector3d(0.1, 0, 0)));
  EXPECT_TRUE(cylinders[1].end.isApprox(Eigen::Vector3d(0.1, 0.2, 0)));
  const std::vector<Eigen::Vector3d> line = tube.Centreline();
  ASSERT_EQ(line.size(), 3u);
  EXPECT_TRUE(line.front().isZero());
  const Tube core = tube.ToTube();
  EXPECT_EQ(core.id, 7u);
  EXPECT_NEAR(core.length(), 0.3, kTol);
}

TEST(TubeGeometry, TreeBecomesATubeGraph) {
  // A Y: trunk 1-2-3 (0.2 m), branches 3-4 (0.1 m) and 3-5-6 (0.15 m) from node 3.
  TubeGeometry tube = Chain({{1, {0, 0, 0}}, {2, {0.1, 0, 0}}, {3, {0.2, 0, 0}}, {4, {0.3, 0.0, 0}}});
  const TubeGeometry fork = Chain({{3, {0.2, 0, 0}}, {5, {0.25, 0.05, 0}}, {6, {0.25, 0.15, 0}}});
  tube.nodes.push_back(fork.nodes[1]);
  tube.nodes.push_back(fork.nodes[2]);
  tube.edges.insert(tube.edges.end(), fork.edges.begin(), fork.edges.end());
  ASSERT_FALSE(tube.IsLinear());
  const Tube core = tube.ToTube();
  EXPECT_EQ(core.id, 7u);
  ASSERT_EQ(core.cylinders.size(), 5u);
  ASSERT_EQ(core.nodes.size(), 4u);     // ends 1, 4, 6 and the junction 3
  ASSERT_EQ(core.branches.size(), 3u);  // 1→3 (two edges), 3→4, 3→6 (two edges)
  EXPECT_TRUE(core.branched());
  EXPECT_NEAR(core.length(), 0.3 + 0.05 * std::sqrt(2.0) + 0.1, 1e-9);
  std::vector<std::uint32_t> counts;
  for (const TubeBranch& b : core.branches) {
    counts.push_back(b.cylinder_count);
    const Cylinder& first = core.cylinders[b.first_cylinder];
    const Cylinder& last = core.cylinders[b.first_cylinder + b.cylinder_count - 1];
    EXPECT_TRUE(first.start.isApprox(core.nodes[b.from_node].p_Bin));
    EXPECT_TRUE(last.end.isApprox(core.nodes[b.to_node].p_Bin));
  }
  std::sort(counts.begin(), counts.end());
  EXPECT_EQ(counts, (std::vector<std::uint32_t>{1, 2, 2}));

  TubeGeometry loop = Chain({{1, {0, 0, 0}}, {2, {0.1, 0, 0}}, {3, {0.1, 0.1, 0}}, {1, {0, 0, 0}}});
  loop.nodes.pop_back();
  EXPECT_THAT([&] { (void)loop.ToTube(); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("tube 7 is not a tree")));
}

TEST(TubeGeometry, CentrelineStartsAtFirstOrderEvenWhenStoredReversed) {
  TubeGeometry tube = Chain({{1, {0, 0, 0}}, {4, {0.1, 0, 0}}, {2, {0.2, 0, 0}}});
  std::swap(tube.edges[0], tube.edges[1]);
  std::swap(tube.nodes[0], tube.nodes[2]);
  const std::vector<Eigen::Vector3d> line = tube.Centreline();
  ASSERT_EQ(line.size(), 3u);
  EXPECT_TRUE(line.front().isZero());
  EXPECT_NEAR(line.back().x(), 0.2, kTol);
}

TEST(TubeGeometry, EdgeOrientationMapsZOntoAxis) {
  const TubeGeometry tube = Chain({{1, {0.1, 0.2, 0.3}}, {2, {0.4, -0.2, 0.1}}});
  const TubeEdge& e = tube.edges[0];
  const Eigen::Vector3d axis = (tube.Node(2).centre - tube.Node(1).centre).normalized();
  EXPECT_TRUE((e.orientation * Eigen::Vector3d::UnitZ()).isApprox(axis, kTol));
  EXPECT_TRUE(e.centre.isApprox(Eigen::Vector3d(0.25, 0.0, 0.2), kTol));
  EXPECT_NEAR(e.length, std::sqrt(0.09 + 0.16 + 0.04), kTol);
  // Straight down: the minimal rotation is undefined; a half turn is used.
  EXPECT_TRUE((RotationFromZ(-Eigen::Vector3d::UnitZ()) * Eigen::Vector3d::UnitZ())
                  .isApprox(-Eigen::Vector3d::UnitZ()));
}

TEST(TubeGeometry, TransformedMovesNodesAndEdges) {
  const TubeGeometry tube = Chain({{1, {0, 0, 0}}, {2, {0, 0, 0.1}}});
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(1, 2, 3);
  const TubeGeometry moved = tube.Transformed(X);
  EXPECT_TRUE(moved.Node(2).centre.isApprox(Eigen::Vector3d(1.1, 2, 3), kTol));
  EXPECT_TRUE(moved.edges[0].centre.isApprox(Eigen::Vector3d(1.05, 2, 3), kTol));
  EXPECT_TRUE(
      (moved.edges[0].orientation * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX(), kTol));
}

TEST(TubeGeometry, BranchedTubeIsNotLinear) {
  TubeGeometry tube = Chain({{1, {0, 0, 0}}, {2, {0.1, 0, 0}}});
  tube.nodes.push_back({3, {0, 0.1, 0}, 0.01});
  TubeEdge e;
  e.name = "e_1_3";
  e.node1 = 1;
  e.node2 = 3;
  e.radius = 0.01;
  tube.edges.push_back(e);
  tube.nodes.push_back({4, {0, -0.1, 0}, 0.01});
  e.name = "e_1_4";
  e.node2 = 4;
  tube.edges.push_back(e);
  EXPECT_FALSE(tube.IsLinear());
  EXPECT_EQ(tube.Degree(1), 3);
  try {
    tube.Centreline();
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("tube 7 is not linear"));
  }
}

TEST(TubeGeometry, UnknownNodeIsAnError) {
  const TubeGeometry tube = Chain({{1, {0, 0, 0}}, {2, {0, 0, 0.1}}});
  try {
    tube.Node(9);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("no node with id 9"));
  }
}

}  // namespace
}  // namespace tubepick::physics
