#include "clients/cli/inputs/scene_files.h"

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "physics/scan_io.h"
#include "physics/tube_config_io.h"

namespace tubepick::cli {
namespace fs = std::filesystem;

SceneData ReadSceneDirectory(const std::string& directory, const CellConfig& fallback_cell) {
  const fs::path dir(directory);
  SceneData scene;
  scene.points_Sensor = ReadCloudFile((dir / kSceneCloudFile).string()).points;
  scene.labels = physics::ReadLabels((dir / kSceneLabelsFile).string());
  if (scene.labels.size() != scene.points_Sensor.size()) {
    throw InvalidArgument(fmt::format("{}: {} labels for {} points in {}", (dir / kSceneLabelsFile).string(),
                                      scene.labels.size(), scene.points_Sensor.size(), kSceneCloudFile));
  }
  scene.tubes_Bin = physics::ReadTubeConfigurations((dir / kSceneTubesFile).string());
  const fs::path cell_path = dir / kSceneCellFile;
  scene.cell = fs::exists(cell_path) ? LoadCellConfig(cell_path.string()) : fallback_cell;
  return scene;
}

std::vector<std::string> FindSceneDirectories(const std::string& root) {
  if (!fs::is_directory(root)) throw InvalidArgument("--scenes: '" + root + "' is not a directory");
  auto is_scene = [](const fs::path& d) {
    return fs::exists(d / kSceneCloudFile) && fs::exists(d / kSceneLabelsFile) &&
           fs::exists(d / kSceneTubesFile);
  };
  std::vector<std::string> found;
  if (is_scene(root)) found.push_back(fs::path(root).string());
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_directory() && is_scene(entry.path())) found.push_back(entry.path().string());
  }
  std::sort(found.begin(), found.end());
  return found;
}

}  // namespace tubepick::cli
