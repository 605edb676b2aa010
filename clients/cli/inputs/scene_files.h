#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "physics/tube_geometry.h"

namespace tubepick::cli {

/// A scene directory as `tubepick scene` writes it and `tubepick eval --scenes` reads it:
///   cloud.ply   the scan, sensor optical frame, in the cell's sensor unit (binary PLY, coloured
///               by label)
///   labels.txt  one ground-truth label per cloud point (tube index ≥ 0 into tubes.txt, −1 bin or
///               ground, −2 outlier)
///   tubes.txt   the settled tubes, Bin frame, in the published `tube_configurations` format
///   cell.yaml   the cell used (bin, sensor pose and unit, tube; DumpCellConfig)
///   scene.json  how it was made (tubes, preset, seed, settling) — informative only
inline constexpr const char* kSceneCloudFile = "cloud.ply";
inline constexpr const char* kSceneLabelsFile = "labels.txt";
inline constexpr const char* kSceneTubesFile = "tubes.txt";
inline constexpr const char* kSceneCellFile = "cell.yaml";
inline constexpr const char* kSceneInfoFile = "scene.json";

struct SceneData {
  Points points_Sensor;
  std::vector<std::int32_t> labels;
  std::vector<physics::TubeGeometry> tubes_Bin;
  CellConfig cell;
};

/// Reads a scene directory; cell.yaml is optional (`fallback_cell` is used without it).
/// @throws InvalidArgument naming the file when one is missing or malformed, or when the label
///         count differs from the point count.
SceneData ReadSceneDirectory(const std::string& directory, const CellConfig& fallback_cell);

/// Every directory at or below `root` holding cloud.ply, labels.txt and tubes.txt, sorted.
/// @throws InvalidArgument when `root` is not a directory.
std::vector<std::string> FindSceneDirectories(const std::string& root);

}  // namespace tubepick::cli
