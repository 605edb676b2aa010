#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/cell_config.h"
#include "core/common/types.h"

namespace tubepick::cli {

/// The embedded default input: tubes dropped into the default cell's bin with Bullet and
/// scanned by the virtual 1920×1200 scanner (no files, no hardware).
struct BuiltInScene {
  Points points_Sensor;
  /// Per point: tube index, −1 bin/ground, −2 outlier.
  std::vector<int> labels;
  std::uint32_t tube_count = 0;
  std::string description;
};

BuiltInScene MakeBuiltInScene(const CellConfig& cell, std::uint32_t tubes, std::uint64_t seed);

}  // namespace tubepick::cli
