#include "physics/bin_drop.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "physics/random_tubes.h"
#include "physics/scene_generator.h"

namespace tubepick::physics {
namespace {

using ::testing::HasSubstr;
/// Contact penetration Bullet may leave, metres.
constexpr double kPenetrationTol = 0.003;

void ExpectBitwiseEqual(const DropResult& a, const DropResult& b) {
  ASSERT_EQ(a.tubes.size(), b.tubes.size());
  EXPECT_EQ(a.steps, b.steps);
  for (std::size_t i = 0; i < a.tubes.size(); ++i) {
    EXPECT_EQ(a.X_BinTube[i].matrix(), b.X_BinTube[i].matrix()) << "tube " << i;
    for (std::size_t k = 0; k < a.tubes[i].nodes.size(); ++k) {
      EXPECT_EQ(a.tubes[i].nodes[k].centre, b.tubes[i].nodes[k].centre);
    }
  }
}

/// Every node centre inside the walls and above the floor; joint spheres (whose centre is R from
/// any surface they touch) by at least R, less the penetration Bullet may leave.
void ExpectInsideBin(const DropResult& result, const BinConfig& bin) {
  for (std::size_t i = 0; i < result.tubes.size(); ++i) {
    SCOPED_TRACE("tube " + std::to_string(i));
    EXPECT_TRUE(result.inside_bin[i]);
    const TubeGeometry& tube = result.tubes[i];
    for (const TubeNode& n : tube.nodes) {
      const double inset = tube.IsJoint(n.id) ? n.radius - kPenetrationTol : 0.0;
      EXPECT_LE(std::abs(n.centre.x()), 0.5 * bin.inner_size.x() - inset);
      EXPECT_LE(std::abs(n.centre.y()), 0.5 * bin.inner_size.y() - inset);
      EXPECT_GE(n.centre.z(), inset);
    }
  }
}

TEST(BinDrop, SameSeedSameSceneDifferentSeedDifferent) {
  SceneParams params;
  params.tube_count = 4;
  const DropResult a = GenerateScene(params, 1);
  const DropResult b = GenerateScene(params, 1);
  const DropResult c = GenerateScene(params, 2);
  ExpectBitwiseEqual(a, b);
  ASSERT_EQ(c.tubes.size(), a.tubes.size());
  EXPECT_NE(a.X_BinTube[0].matrix(), c.X_BinTube[0].matrix());
}

TEST(BinDrop, TenTubesSettleInsideTheBin) {
  SceneParams params;
  const DropResult result = GenerateScene(params, 3);
  ASSERT_EQ(result.tubes.size(), 10u);
  EXPECT_TRUE(result.settled);
  EXPECT_LT(result.simulated_time, params.drop.max_time + 10 * params.drop.spawn_interval);
  ExpectInsideBin(result, params.bin);
  for (std::size_t i = 0; i < result.tubes.size(); ++i)
    EXPECT_EQ(result.tubes[i].id, static_cast<int>(i) + 1);
}

TEST(BinDrop, ResultIsInputMovedRigidly) {
  const std::vector<TubeGeometry> tubes = GenerateRandomTubes(2, RandomTubeParams::SetA(), 9);
  const BinConfig bin;
  const DropResult result = DropTubes(tubes, bin, DropParams{}, 4);
  ASSERT_EQ(result.tubes.size(), 2u);
  for (std::size_t i = 0; i < tubes.size(); ++i) {
    const TubeGeometry expected = tubes[i].Transformed(result.X_BinTube[i]);
    for (std::size_t k = 0; k < expected.nodes.size(); ++k) {
      EXPECT_TRUE(result.tubes[i].nodes[k].centre.isApprox(expected.nodes[k].centre, 1e-12));
    }
    EXPECT_NEAR(result.tubes[i].Length(), tubes[i].Length(), 1e-9);
  }
}

TEST(BinDrop, PlanarTubeComesToRestFlatOnTheFloor) {
  // A planar zig-zag: if the centre of mass or the inertia were wrong it would not lie flat.
  TubeGeometry tube;
  tube.id = 1;
  const std::vector<Eigen::Vector3d> p{{-0.2, 0, 0}, {-0.05, 0.05, 0}, {0.05, -0.02, 0}, {0.2, 0.03, 0}};
  for (int i = 0; i < 4; ++i) tube.nodes.push_back({i + 1, p[i], 0.0125});
  for (int i = 0; i < 3; ++i) {
    TubeEdge e;
    e.node1 = i + 1;
    e.node2 = i + 2;
    e.name = "e";
    e.radius = 0.0125;
    SetEdgeFromNodes(tube, e);
    tube.edges.push_back(e);
  }
  const BinConfig bin;
  const DropResult result = DropTubes({tube}, bin, DropParams{}, 5);
  EXPECT_TRUE(result.settled);
  for (const TubeNode& n : result.tubes[0].nodes) EXPECT_NEAR(n.centre.z(), 0.0125, kPenetrationTol);
}

TEST(BinDrop, BranchedTubesAndWaitForRest) {
  SceneParams params;
  params.tube_count = 3;
  params.tubes = RandomTubeParams::SetC();
  params.drop.wait_for_rest = true;
  const DropResult result = GenerateScene(params, 6);
  EXPECT_TRUE(result.settled);
  ExpectInsideBin(result, params.bin);
}

TEST(BinDrop, EmptyInputAndInvalidParams) {
  const DropResult empty = DropTubes({}, BinConfig{}, DropParams{}, 1);
  EXPECT_TRUE(empty.settled);
  EXPECT_TRUE(empty.tubes.empty());
  DropParams params;
  params.time_step = 0.0;
  try {
    DropTubes({}, BinConfig{}, params, 1);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("time_step = 0"));
  }
}

}  // namespace
}  // namespace tubepick::physics
