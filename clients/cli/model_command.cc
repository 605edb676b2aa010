#include "clients/cli/model_command.h"

#include <fmt/core.h>

#include <memory>

#include "clients/cli/builtin_scene.h"
#include "clients/cli/cli_inputs.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/model_tubes.h"
#include "server/proto_convert.h"

namespace tubepick::cli {
namespace {

struct ModelOptions {
  CommonOptions common;
  std::string cloud_path;
  std::string unit;  // empty = the cell's sensor unit
  std::string json_path;
  std::string dump_dir;
  std::uint32_t builtin_tubes = 10;
};

void PrintSummary(const ModelingResult& r, const std::string& source) {
  fmt::print("{}\n", source);
  fmt::print(
      "{} points ({} non-finite dropped) -> {} filtered -> {} segments -> {} cylinders -> {} tubes in {:.3f} "
      "s\n",
      r.input_points, r.dropped_non_finite, r.filtered.size(), r.segment_count, r.cylinder_count,
      r.tubes.size(), r.total_seconds);
  fmt::print("{:>5} {:>9} {:>9}  {:<30} {:<30}\n", "tube", "length_m", "cylinders", "end A (x, y, z) m",
             "end B (x, y, z) m");
  for (const Tube& t : r.tubes) {
    const Eigen::Vector3d a = t.cylinders.front().start, b = t.cylinders.back().end;
    fmt::print("{:>5} {:>9.3f} {:>9}  ({:+.3f}, {:+.3f}, {:+.3f})       ({:+.3f}, {:+.3f}, {:+.3f})\n", t.id,
               t.length(), t.cylinders.size(), a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
  }
  fmt::print("stages:");
  for (const StageTiming& s : r.timings) fmt::print(" {} {:.1f} ms;", s.stage, 1e3 * s.seconds);
  fmt::print("\npoints: ");
  for (const StepCount& c : r.counts) fmt::print(" {} {};", c.step, c.points);
  fmt::print("\n");
}

void Run(const ModelOptions& o) {
  const CellConfig cell = LoadCell(o.common);
  const Params params = LoadParamsFor(o.common);

  Points points_Sensor;
  LengthUnit unit = o.unit.empty() ? cell.sensor.unit : ParseLengthUnit(o.unit, "--unit");
  std::string source;
  if (o.cloud_path.empty()) {
    BuiltInScene scene = MakeBuiltInScene(cell, o.builtin_tubes, o.common.seed);
    points_Sensor = std::move(scene.points_Sensor);
    unit = LengthUnit::kMetre;
    source = "built-in scene: " + scene.description;
  } else {
    CloudFile file = ReadCloudFile(o.cloud_path);
    points_Sensor = std::move(file.points);
    source = fmt::format("cloud {} ({}, unit {})", o.cloud_path, file.format, ToString(unit));
  }

  ModelingInput input;
  input.points_Sensor = &points_Sensor;
  input.unit = unit;
  input.X_BinSensor = cell.sensor.X_BinSensor;
  input.bin = cell.bin;
  input.seed = o.common.seed;
  const ModelingResult result = ModelTubes(input, params.modeling);

  PrintSummary(result, source + fmt::format(", profile {}, seed {}", o.common.profile, o.common.seed));
  if (!o.json_path.empty()) {
    WriteTextFile(o.json_path, ToJson(ToModelTubesResponse(result, o.common.profile, o.common.seed)));
    fmt::print("wrote {}\n", o.json_path);
  }
  if (!o.dump_dir.empty()) {
    DumpStages(result, o.dump_dir);
    fmt::print("wrote stage clouds to {}/\n", o.dump_dir);
  }
}

}  // namespace

void AddModelCommand(CLI::App& app) {
  auto o = std::make_shared<ModelOptions>();
  CLI::App* cmd = app.add_subcommand("model", "Model the tubes of a point cloud (thesis Algorithm 1)");
  cmd->add_option("--cloud", o->cloud_path, "PLY or PCD cloud in the sensor frame (default: built-in scene)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--cell", o->common.cell_path, "Cell YAML (default: embedded default cell)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--profile", o->common.profile, "Parameter profile")
      ->check(CLI::IsMember({"fast", "thesis"}))
      ->capture_default_str();
  cmd->add_option("--params", o->common.params_path, "Params YAML applied on top of the profile")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", o->common.seed, "Seed of every random step")->capture_default_str();
  cmd->add_option("--unit", o->unit, "Unit of the cloud file (default: the cell's sensor.unit)")
      ->check(CLI::IsMember({"m", "mm"}));
  cmd->add_option("--json", o->json_path, "Write the ModelTubesResponse as proto3 JSON");
  cmd->add_option("--dump-stages", o->dump_dir, "Write intermediate clouds (PLY) into this directory");
  cmd->add_option("--tubes", o->builtin_tubes, "Tubes in the built-in scene")
      ->check(CLI::Range(1, 30))
      ->capture_default_str();
  cmd->callback([o] { Run(*o); });
}

}  // namespace tubepick::cli
