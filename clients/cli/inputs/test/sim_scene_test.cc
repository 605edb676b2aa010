// The cell a generated preset describes.
#include "clients/cli/inputs/sim_scene.h"

#include <gtest/gtest.h>

namespace tubepick::cli {
namespace {

TEST(CellForPreset, TreesAreBranchedAndOnlyYPieceTreesExpectAWye) {
  const CellConfig cell;
  EXPECT_EQ(CellForPreset(cell, "A").tube.topology, TubeTopology::kLinear);
  EXPECT_EQ(CellForPreset(cell, "A").tube.junction_shape, JunctionShape::kAny);
  EXPECT_EQ(CellForPreset(cell, "C").tube.topology, TubeTopology::kBranched);
  EXPECT_NEAR(CellForPreset(cell, "C").tube.length, 0.75, 1e-9);
  EXPECT_EQ(CellForPreset(cell, "C").tube.junction_shape, JunctionShape::kAny);
  EXPECT_EQ(CellForPreset(cell, "CY").tube.junction_shape, JunctionShape::kWye);
  // A cell that states its shape keeps it.
  CellConfig tees;
  tees.tube.junction_shape = JunctionShape::kTee;
  EXPECT_EQ(CellForPreset(tees, "CY").tube.junction_shape, JunctionShape::kTee);
  EXPECT_EQ(PresetJunctionShape("CY"), JunctionShape::kWye);
  EXPECT_EQ(PresetJunctionShape("B"), JunctionShape::kAny);
}

}  // namespace
}  // namespace tubepick::cli
