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

TEST(SimScene, ThePresetsJunctionLayoutComesFromItsBranches) {
  // Set C: a 0.30 m trunk with a junction at each end, branches of 0.10 and 0.15 m.
  for (const char* preset : {"C", "CY"}) {
    const JunctionLayout layout = PresetJunctionLayout(preset);
    EXPECT_EQ(layout.junctions, 2u) << preset;
    EXPECT_DOUBLE_EQ(layout.junction_spacing, 0.30) << preset;
    EXPECT_DOUBLE_EQ(layout.branch_length, 0.15) << preset;
  }
  EXPECT_FALSE(PresetJunctionLayout("A").known());
  CellConfig cell;
  EXPECT_EQ(CellForPreset(cell, "C").tube.layout.junctions, 2u);
  // A cell that states a layout keeps it.
  cell.tube.layout.junction_spacing = 0.25;
  EXPECT_DOUBLE_EQ(CellForPreset(cell, "C").tube.layout.junction_spacing, 0.25);
  EXPECT_EQ(CellForPreset(cell, "C").tube.layout.junctions, 0u);
}

}  // namespace
}  // namespace tubepick::cli
