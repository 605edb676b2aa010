#include "clients/cli/inputs/sim_scene.h"

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
  return cell;
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
