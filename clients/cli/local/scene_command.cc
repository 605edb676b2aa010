#include "clients/cli/local/scene_command.h"

#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "clients/cli/inputs/cli_inputs.h"
#include "clients/cli/inputs/scene_files.h"
#include "clients/cli/inputs/sim_scene.h"
#include "physics/scan_io.h"
#include "physics/tube_config_io.h"

namespace tubepick::cli {
namespace {

struct SceneOptions {
  CommonOptions common;
  int tubes = 10;
  std::string preset = "A";
  std::string out_dir;
};

void Run(const SceneOptions& o) {
  // The cell written with the scene describes its tubes (length, topology).
  const CellConfig cell = CellForPreset(LoadCell(o.common), o.preset);
  const auto t0 = std::chrono::steady_clock::now();
  SimulatedScene scene = SimulateScene(cell, o.tubes, o.preset, o.common.seed);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The scanner works in metres; the file carries the cell's sensor unit.
  if (cell.sensor.unit != LengthUnit::kMetre) {
    const float scale = static_cast<float>(1.0 / MetresPer(cell.sensor.unit));
    for (auto& p : scene.scan.points_Sensor) p *= scale;
  }
  const std::filesystem::path dir(o.out_dir);
  std::filesystem::create_directories(dir);
  physics::WriteScan((dir / kSceneCloudFile).string(), (dir / kSceneLabelsFile).string(), scene.scan);
  physics::WriteTubeConfigurations((dir / kSceneTubesFile).string(), scene.drop.tubes);
  WriteTextFile((dir / kSceneCellFile).string(), DumpCellConfig(cell));

  std::uint32_t outside = 0;
  for (bool inside : scene.drop.inside_bin) outside += inside ? 0 : 1;
  std::vector<std::uint64_t> points_per_tube(scene.drop.tubes.size(), 0);
  std::uint64_t bin_points = 0;
  for (std::int32_t label : scene.scan.labels) {
    if (label >= 0 && static_cast<std::size_t>(label) < points_per_tube.size()) ++points_per_tube[label];
    if (label == physics::kBinLabel) ++bin_points;
  }
  nlohmann::json info;
  info["tubes"] = o.tubes;
  info["preset"] = o.preset;
  info["seed"] = o.common.seed;
  info["settled"] = scene.drop.settled;
  info["simulated_seconds"] = scene.drop.simulated_time;
  info["tubes_outside_bin"] = outside;
  info["points"] = scene.scan.points_Sensor.size();
  info["points_per_tube"] = points_per_tube;
  info["bin_points"] = bin_points;
  info["outliers"] = scene.scan.outliers;
  info["grazing_dropped"] = scene.scan.grazing_dropped;
  info["unit"] = ToString(cell.sensor.unit);
  WriteTextFile((dir / kSceneInfoFile).string(), info.dump(2) + "\n");

  fmt::print(
      "scene: {} set-{} tubes, seed {}: {} ({:.1f} s simulated{}), {} points ({} outliers), {:.1f} s\n",
      o.tubes, o.preset, o.common.seed, scene.drop.settled ? "settled" : "NOT settled",
      scene.drop.simulated_time, outside ? fmt::format(", {} outside the bin", outside) : "",
      scene.scan.points_Sensor.size(), scene.scan.outliers, seconds);
  fmt::print("wrote {}/{{{}, {}, {}, {}, {}}}\n", dir.string(), kSceneCloudFile, kSceneLabelsFile,
             kSceneTubesFile, kSceneCellFile, kSceneInfoFile);
}

}  // namespace

void AddSceneCommand(CLI::App& app) {
  auto o = std::make_shared<SceneOptions>();
  CLI::App* cmd =
      app.add_subcommand("scene", "Drop random tubes into the bin, scan them, write cloud + ground truth");
  cmd->add_option("--tubes", o->tubes, "Number of tubes")->check(CLI::Range(1, 30))->capture_default_str();
  cmd->add_option("--preset", o->preset,
                  "Tube shape set (thesis / dataset sets A, B, C; CY: set C with Y-pieces)")
      ->check(CLI::IsMember({"A", "B", "C", "CY"}))
      ->capture_default_str();
  cmd->add_option("--seed", o->common.seed, "Seed of the tube shapes, the drop and the scan")
      ->capture_default_str();
  cmd->add_option("--out", o->out_dir, "Scene directory to write")->required();
  cmd->add_option("--cell", o->common.cell_path, "Cell YAML (default: embedded default cell)")
      ->check(CLI::ExistingFile);
  cmd->callback([o] { Run(*o); });
}

}  // namespace tubepick::cli
