// Tube bodies of the simulated cell: rubber trees as link chains.
#include "devices/sim/sim_tubes.h"

#include <map>
#include <random>

#include <gtest/gtest.h>

#include "physics/random_tubes.h"

namespace tubepick::devices::sim {
namespace {

TEST(AddSimTube, RubberTreeSharesItsMassOutAndMeetsAtItsJunctions) {
  const physics::RandomTubeParams shape = physics::RandomTubeParams::SetC();
  std::mt19937_64 rng(3);
  const physics::TubeGeometry tree = physics::GenerateRandomTube(shape, 1, rng);
  ASSERT_FALSE(tree.IsLinear());
  physics::BulletWorld world;
  TubeBodyOptions options;
  options.rubber = true;
  options.mass = 0.2;
  const SimTube tube = AddSimTube(world, tree, 0, options);
  ASSERT_EQ(tube.link_nodes.size(), tube.links.size());
  ASSERT_GT(tube.links.size(), 6u);
  double mass = 0.0;
  std::map<int, int> links_at;  // node id -> links ending there
  for (std::size_t l = 0; l < tube.links.size(); ++l) {
    mass += tube.links[l].mass;
    ++links_at[tube.link_nodes[l].first];
    ++links_at[tube.link_nodes[l].second];
  }
  EXPECT_NEAR(mass, options.mass, 1e-12);
  // Every tree node of degree d is the end of d links; each junction is held by d − 1 joints, each
  // chain joint by one: links − 1 joints in all (a tree of links).
  for (const physics::TubeNode& n : tree.nodes) {
    if (tree.Degree(n.id) != 2) {
      EXPECT_EQ(links_at[n.id], tree.Degree(n.id)) << "node " << n.id;
    }
  }
  EXPECT_EQ(tube.joints.size(), tube.links.size() - 1);
  // As built, the current geometry is the tree's: its free ends and junctions where they were.
  const physics::TubeGeometry now = CurrentGeometry(tube);
  for (const physics::TubeNode& n : tree.nodes) {
    if (tree.Degree(n.id) == 2) continue;
    EXPECT_LT((now.Node(n.id).centre - n.centre).norm(), 1e-9) << "node " << n.id;
  }
}

}  // namespace
}  // namespace tubepick::devices::sim
