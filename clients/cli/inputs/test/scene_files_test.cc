// Scene directories as `tubepick scene` writes them and `tubepick eval --scenes` reads them.
#include "clients/cli/inputs/scene_files.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "physics/scan_io.h"
#include "physics/tube_config_io.h"

namespace tubepick::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr double kTol = 1e-12;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// A scene directory of three points labelled tube 0, background, outlier, and no tubes.
fs::path WriteScene(const std::string& name) {
  const fs::path dir = FreshDir(name);
  WritePly((dir / kSceneCloudFile).string(), Points(3, Eigen::Vector3f(0.f, 0.f, 1.f)));
  physics::WriteLabels((dir / kSceneLabelsFile).string(), {0, -1, -2});
  physics::WriteTubeConfigurations((dir / kSceneTubesFile).string(), {});
  return dir;
}

TEST(SceneFiles, TheCellWrittenBesideTheSceneIsTheOneReadBack) {
  CellConfig cell;
  cell.bin.inner_size = {0.7, 0.5, 0.25};
  cell.sensor.unit = LengthUnit::kMillimetre;
  cell.sensor.X_BinSensor.translation() = Eigen::Vector3d(0.01, -0.02, 1.3);
  cell.tube = {.radius = 0.01, .length = 0.4, .mass = 0.07, .layout = {}};
  const fs::path dir = WriteScene("tubepick_scene_files_cell");
  std::ofstream(dir / kSceneCellFile) << DumpCellConfig(cell);  // what `tubepick scene` writes
  const SceneData scene = ReadSceneDirectory(dir.string(), CellConfig{});
  EXPECT_EQ(scene.points_Sensor.size(), 3u);
  EXPECT_EQ(scene.labels, (std::vector<std::int32_t>{0, -1, -2}));
  EXPECT_TRUE(scene.tubes_Bin.empty());
  EXPECT_TRUE(scene.cell.bin.inner_size.isApprox(cell.bin.inner_size, kTol));
  EXPECT_EQ(scene.cell.sensor.unit, LengthUnit::kMillimetre);
  EXPECT_TRUE(scene.cell.sensor.X_BinSensor.isApprox(cell.sensor.X_BinSensor, kTol));
  EXPECT_NEAR(scene.cell.tube.mass, 0.07, kTol);
}

TEST(SceneFiles, WithoutACellFileTheFallbackCellApplies) {
  CellConfig fallback;
  fallback.tube.radius = 0.02;
  const SceneData scene = ReadSceneDirectory(WriteScene("tubepick_scene_files_fallback").string(), fallback);
  EXPECT_EQ(scene.cell.tube.radius, 0.02);
}

TEST(SceneFiles, FindsOnlyCompleteSceneDirectoriesSorted) {
  const fs::path root = FreshDir("tubepick_scene_files_find");
  for (const char* name : {"b", "a", "incomplete"}) {
    fs::create_directories(root / name);
    std::ofstream(root / name / kSceneCloudFile) << "x";
    std::ofstream(root / name / kSceneLabelsFile) << "x";
    if (std::string(name) != "incomplete") std::ofstream(root / name / kSceneTubesFile) << "x";
  }
  const std::vector<std::string> found = FindSceneDirectories(root.string());
  ASSERT_EQ(found.size(), 2u);
  EXPECT_THAT(found[0], HasSubstr("/a"));
  EXPECT_THAT(found[1], HasSubstr("/b"));
  EXPECT_THROW(FindSceneDirectories((root / "none").string()), InvalidArgument);
}

TEST(SceneFiles, ALabelCountOtherThanThePointCountIsAnErrorNamingTheFile) {
  const fs::path dir = FreshDir("tubepick_scene_files_labels");
  WritePly((dir / kSceneCloudFile).string(), Points(3, Eigen::Vector3f(0.f, 0.f, 1.f)));
  std::ofstream(dir / kSceneLabelsFile) << "0\n0\n";
  std::ofstream(dir / kSceneTubesFile) << "";
  try {
    ReadSceneDirectory(dir.string(), CellConfig{});
    FAIL() << "2 labels for 3 points must throw";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr(kSceneLabelsFile));
  }
}

}  // namespace
}  // namespace tubepick::cli
