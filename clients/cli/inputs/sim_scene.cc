#include "clients/cli/inputs/sim_scene.h"

#include "physics/scene_generator.h"

namespace tubepick::cli {

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
