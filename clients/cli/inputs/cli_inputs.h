#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "core/modeling/model_tubes.h"
#include "core/params.h"

namespace tubepick::cli {

/// Options every planning command shares: cell, profile, params overrides, seed.
struct CommonOptions {
  std::string cell_path;  ///< empty = embedded default cell
  std::string profile = "fast";
  std::string params_path;  ///< empty = the profile as is
  std::uint64_t seed = 0;
};

/// What `model` and `plan` read: a cloud file or the built-in scene, with the common options.
struct InputOptions {
  CommonOptions common;
  std::string cloud_path;  ///< empty = the built-in scene
  std::string unit;        ///< empty = the cell's sensor unit
  std::uint32_t builtin_tubes = 10;
};

/// Registers --cloud, --cell, --profile, --params, --seed, --unit and --tubes on `cmd`.
void AddInputOptions(CLI::App* cmd, InputOptions& options);

/// A cloud ready for ModelTubes, and where it came from.
struct CloudInput {
  Points points_Sensor;
  LengthUnit unit = LengthUnit::kMetre;
  std::string source;
};

/// Reads --cloud (in --unit or the cell's unit) or makes the built-in scene.
CloudInput LoadCloudInput(const InputOptions& options, const CellConfig& cell);

/// The modeling input for a cloud in the sensor frame, in `unit`, seen in `cell` (it points into
/// `points_Sensor`, which must outlive it), keeping the raw points in raw_region_Bin
/// (ModelingInput::raw_region_Bin: RawRegionForPlanning before PlanPick, None for modeling alone).
ModelingInput MakeModelingInput(const Points& points_Sensor, LengthUnit unit, const CellConfig& cell,
                                std::uint64_t seed, const RawRegion& raw_region_Bin);

/// The cell from --cell, or the embedded default (ARCHITECTURE.md's example).
CellConfig LoadCell(const CommonOptions& options);
/// The profile overridden by --params.
Params LoadParamsFor(const CommonOptions& options);

/// Writes text to a file, creating parent directories. @throws InvalidArgument on failure.
void WriteTextFile(const std::string& path, const std::string& text);

}  // namespace tubepick::cli
