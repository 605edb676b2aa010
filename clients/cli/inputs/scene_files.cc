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

std::string FormatCellYaml(const CellConfig& cell) {
  auto pose = [](const Eigen::Isometry3d& X) {
    const Eigen::Vector3d p = X.translation();
    const Eigen::Quaterniond q(X.rotation());
    return fmt::format(
        "    position: [{:.9g}, {:.9g}, {:.9g}]\n    orientation_xyzw: [{:.9g}, {:.9g}, {:.9g}, {:.9g}]\n",
        p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
  };
  const Eigen::Vector3d& size = cell.bin.inner_size;
  std::string text = "# Cell written by tubepick scene (see ARCHITECTURE.md). SI units.\n";
  text += fmt::format("bin:\n  inner_size: [{:.9g}, {:.9g}, {:.9g}]\n", size.x(), size.y(), size.z());
  text += "sensor:\n  pose_in_bin:\n" + pose(cell.sensor.X_BinSensor);
  text += fmt::format("  unit: {}\n", ToString(cell.sensor.unit));
  text += fmt::format("tube:\n  radius: {:.9g}\n  length: {:.9g}\n  mass: {:.9g}\n", cell.tube.radius,
                      cell.tube.length, cell.tube.mass);
  text += "place:\n  pose_in_bin:\n" + pose(cell.place.X_BinPlace);
  return text;
}

}  // namespace tubepick::cli
