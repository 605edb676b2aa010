#include "clients/cli/local/model_command.h"

#include <fmt/core.h>

#include <memory>

#include "clients/cli/inputs/cli_inputs.h"
#include "core/common/tube_graph.h"
#include "core/modeling/model_tubes.h"
#include "wire/proto_convert.h"
#include "wire/response_convert.h"

namespace tubepick::cli {
namespace {

struct ModelOptions {
  InputOptions input;
  std::string json_path;
  std::string dump_dir;
};

void PrintSummary(const ModelingResult& r, const std::string& source) {
  fmt::print("{}\n", source);
  fmt::print(
      "{} points ({} non-finite dropped) -> {} filtered -> {} segments -> {} cylinders -> {} tubes in {:.3f} "
      "s\n",
      r.input_points, r.dropped_non_finite, r.filtered.size(), r.segment_count, r.cylinder_count,
      r.tubes.size(), r.total_seconds);
  fmt::print("{:>5} {:>9} {:>8} {:>9}  {}\n", "tube", "length_m", "branches", "cylinders",
             "nodes: ends, then junctions (x, y, z) m");
  for (const Tube& t : r.tubes) {
    const std::vector<TubeNode> nodes = NodesOf(t);
    const std::vector<std::uint32_t> degree = NodeDegrees(t);
    std::string ends, junctions;
    for (std::size_t n = 0; n < nodes.size(); ++n) {
      const Eigen::Vector3d& p = nodes[n].p_Bin;
      (degree[n] == 1 ? ends : junctions) += fmt::format(" ({:+.3f}, {:+.3f}, {:+.3f})", p.x(), p.y(), p.z());
    }
    fmt::print("{:>5} {:>9.3f} {:>8} {:>9} {}{}\n", t.id, t.length(), BranchesOf(t).size(),
               t.cylinders.size(), ends, junctions.empty() ? "" : "  junctions:" + junctions);
  }
  fmt::print("stages:");
  for (const StageTiming& s : r.timings) fmt::print(" {} {:.1f} ms;", s.stage, 1e3 * s.seconds);
  fmt::print("\npoints: ");
  for (const StepCount& c : r.counts) fmt::print(" {} {};", c.step, c.points);
  fmt::print("\n");
}

void Run(const ModelOptions& o) {
  const CommonOptions& common = o.input.common;
  const CellConfig cell = LoadCell(common);
  const Params params = LoadParamsFor(common);

  const CloudInput cloud = LoadCloudInput(o.input, cell);
  const ModelingInput input =
      MakeModelingInput(cloud.points_Sensor, cloud.unit, cell, o.input.common.seed, RawRegion::None());
  const ModelingResult result = ModelTubes(input, params.modeling);

  PrintSummary(result, cloud.source + fmt::format(", profile {}, seed {}", common.profile, common.seed));
  if (!o.json_path.empty()) {
    WriteTextFile(o.json_path, ToJson(ToModelTubesResponse(result, common.profile, common.seed)));
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
  AddInputOptions(cmd, o->input);
  cmd->add_option("--json", o->json_path, "Write the ModelTubesResponse as proto3 JSON");
  cmd->add_option("--dump-stages", o->dump_dir, "Write intermediate clouds (PLY) into this directory");
  cmd->callback([o] { Run(*o); });
}

}  // namespace tubepick::cli
