#include "clients/cli/inputs/cli_inputs.h"

#include <filesystem>
#include <fstream>

#include "clients/cli/inputs/builtin_scene.h"
#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"

namespace tubepick::cli {

CellConfig LoadCell(const CommonOptions& options) {
  if (options.cell_path.empty()) return CellConfig{};
  return LoadCellConfig(options.cell_path);
}

Params LoadParamsFor(const CommonOptions& options) {
  Params params = ProfileParams(options.profile);
  if (!options.params_path.empty()) params = LoadParams(options.params_path, params);
  return params;
}

void AddInputOptions(CLI::App* cmd, InputOptions& o) {
  cmd->add_option("--cloud", o.cloud_path, "PLY or PCD cloud in the sensor frame (default: built-in scene)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--cell", o.common.cell_path, "Cell YAML (default: embedded default cell)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--profile", o.common.profile, "Parameter profile")
      ->check(CLI::IsMember({"fast", "thesis"}))
      ->capture_default_str();
  cmd->add_option("--params", o.common.params_path, "Params YAML applied on top of the profile")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", o.common.seed, "Seed of every random step")->capture_default_str();
  cmd->add_option("--unit", o.unit, "Unit of the cloud file (default: the cell's sensor.unit)")
      ->check(CLI::IsMember({"m", "mm"}));
  cmd->add_option("--tubes", o.builtin_tubes, "Tubes in the built-in scene")
      ->check(CLI::Range(1, 30))
      ->capture_default_str();
}

CloudInput LoadCloudInput(const InputOptions& o, const CellConfig& cell) {
  CloudInput input;
  if (o.cloud_path.empty()) {
    BuiltInScene scene = MakeBuiltInScene(cell, o.builtin_tubes, o.common.seed);
    input.points_Sensor = std::move(scene.points_Sensor);
    input.unit = LengthUnit::kMetre;
    input.source = "built-in scene: " + scene.description;
    return input;
  }
  CloudFile file = ReadCloudFile(o.cloud_path);
  input.points_Sensor = std::move(file.points);
  input.unit = o.unit.empty() ? cell.sensor.unit : ParseLengthUnit(o.unit, "--unit");
  input.source = "cloud " + o.cloud_path + " (" + file.format + ", unit " + ToString(input.unit) + ")";
  return input;
}

ModelingInput MakeModelingInput(const Points& points_Sensor, LengthUnit unit, const CellConfig& cell,
                                std::uint64_t seed, const RawRegion& raw_region_Bin) {
  ModelingInput input = ModelingInputFor(cell);
  input.raw_region_Bin = raw_region_Bin;
  input.points_Sensor = &points_Sensor;
  input.unit = unit;
  input.seed = seed;
  return input;
}

void WriteTextFile(const std::string& path, const std::string& text) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InvalidArgument("cannot write '" + path + "'");
  out << text;
  // Flushed here, not in the destructor, so that a full disk is an error and not a silent loss.
  if (!out.flush()) throw InvalidArgument("error writing '" + path + "' (disk full?)");
}

}  // namespace tubepick::cli
