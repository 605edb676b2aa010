#include "clients/cli/inputs/builtin_scene.h"

#include <fmt/core.h>

#include "physics/scene_generator.h"
#include "physics/virtual_scanner.h"

namespace tubepick::cli {

BuiltInScene MakeBuiltInScene(const CellConfig& cell, std::uint32_t tubes, std::uint64_t seed) {
  physics::SceneParams scene;
  scene.tube_count = static_cast<int>(tubes);
  scene.tubes = physics::RandomTubeParams::SetA();
  scene.tubes.radius = cell.tube.radius;
  scene.bin = cell.bin;
  const physics::DropResult drop = physics::GenerateScene(scene, seed);
  physics::ScanResult scan = physics::ScanScene(drop.tubes, cell, physics::ScannerParams{}, seed);
  BuiltInScene out;
  out.points_Sensor = std::move(scan.points_Sensor);
  out.labels.assign(scan.labels.begin(), scan.labels.end());
  out.tube_count = tubes;
  out.description =
      fmt::format("{} set-A tubes dropped into a {:.2f} x {:.2f} m bin (seed {}), scanned at 1920x1200",
                  tubes, cell.bin.inner_size.x(), cell.bin.inner_size.y(), seed);
  return out;
}

}  // namespace tubepick::cli
