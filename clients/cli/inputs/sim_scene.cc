#include "clients/cli/inputs/sim_scene.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "physics/scene_generator.h"

namespace tubepick::cli {

CellConfig CellForPreset(CellConfig cell, const std::string& preset) {
  const physics::RandomTubeParams tubes = physics::RandomTubeParams::Preset(preset);
  double length = 0.0;
  for (const physics::TubeBranchSpec& b : tubes.branches) length += b.length;
  cell.tube.length = length;
  if (tubes.branches.size() > 1 && cell.tube.topology == TubeTopology::kLinear) {
    cell.tube.topology = TubeTopology::kBranched;
  }
  if (cell.tube.junction_shape == JunctionShape::kAny) cell.tube.junction_shape = PresetJunctionShape(preset);
  if (!cell.tube.layout.known()) cell.tube.layout = PresetJunctionLayout(preset);
  return cell;
}

JunctionLayout PresetJunctionLayout(const std::string& preset) {
  const physics::RandomTubeParams tubes = physics::RandomTubeParams::Preset(preset);
  std::map<int, int> degree;
  for (const physics::TubeBranchSpec& b : tubes.branches) {
    ++degree[b.from_node];
    ++degree[b.to_node];
  }
  JunctionLayout layout;
  for (const auto& [node, d] : degree) layout.junctions += d >= 3 ? 1 : 0;
  bool one_spacing = true;
  for (const physics::TubeBranchSpec& b : tubes.branches) {
    const bool from = degree[b.from_node] >= 3, to = degree[b.to_node] >= 3;
    if (from && to) {
      one_spacing = one_spacing && (layout.junction_spacing == 0.0 || layout.junction_spacing == b.length);
      layout.junction_spacing = b.length;
    } else if (from || to) {
      layout.branch_length = std::max(layout.branch_length, b.length);
    }
  }
  if (!one_spacing) layout.junction_spacing = 0.0;  // runs of several lengths: not one spacing
  return layout;
}

JunctionShape PresetJunctionShape(const std::string& preset) {
  const physics::RandomTubeParams tubes = physics::RandomTubeParams::Preset(preset);
  // Set CY's branches leave their split node 120° from the trunk and 180° apart in azimuth: the
  // arms of a symmetric Y-piece. Set C's leave in random directions: any shape.
  const bool wyes = tubes.branches.size() > 1 &&
                    std::all_of(tubes.branches.begin() + 1, tubes.branches.end(), [](const auto& b) {
                      return !b.split_random && std::abs(b.split_angle - 2.0 * M_PI / 3.0) < 1e-9;
                    });
  return wyes ? JunctionShape::kWye : JunctionShape::kAny;
}

SimulatedScene SimulateScene(const CellConfig& cell, int tube_count, const std::string& preset,
                             std::uint64_t seed) {
  physics::SceneParams params;
  params.tube_count = tube_count;
  params.tubes = physics::RandomTubeParams::Preset(preset);
  params.tubes.radius = cell.tube.radius;
  params.bin = cell.bin;
  params.drop.tube_mass = cell.tube.mass;
  SimulatedScene scene;
  scene.drop = physics::GenerateScene(params, seed);
  scene.scan = physics::ScanScene(scene.drop.tubes, cell, physics::ScannerParams{}, seed);
  return scene;
}

}  // namespace tubepick::cli
