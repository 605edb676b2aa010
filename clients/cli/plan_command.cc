#include "clients/cli/plan_command.h"

#include <fmt/core.h>

#include <memory>

#include "clients/cli/builtin_scene.h"
#include "clients/cli/cli_inputs.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"
#include "core/planning/plan_placement.h"
#include "physics/trajectory_simulator.h"
#include "server/proto_convert.h"

namespace tubepick::cli {
namespace {

struct PlanOptions {
  CommonOptions common;
  std::string cloud_path;
  std::string unit;
  std::string json_path;
  std::uint32_t builtin_tubes = 10;
  bool no_sim = false;
  std::uint32_t sim_threads = 0;
  std::uint32_t show = 5;
};

const char* OcclusionName(Occlusion o) {
  switch (o) {
    case Occlusion::kNone:
      return "none";
    case Occlusion::kWeak:
      return "weak";
    case Occlusion::kStrong:
      return "strong";
    case Occlusion::kUnspecified:
      break;
  }
  return "-";
}

void Run(const PlanOptions& o) {
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
    points_Sensor = ReadCloudFile(o.cloud_path).points;
    source = "cloud " + o.cloud_path;
  }

  ModelingInput input;
  input.points_Sensor = &points_Sensor;
  input.unit = unit;
  input.X_BinSensor = cell.sensor.X_BinSensor;
  input.bin = cell.bin;
  input.seed = o.common.seed;
  const ModelingResult modeling = ModelTubes(input, params.modeling);

  physics::TrajectorySimParams sim;
  sim.bin = cell.bin;
  sim.tube_mass = cell.tube.mass;
  sim.disp_max = params.planning.cost.max_displacement;
  sim.threads = static_cast<int>(o.sim_threads);
  physics::BulletTrajectoryEvaluator evaluator(sim);
  PickPlanResult plan =
      PlanPick(modeling, cell, params.planning, o.no_sim ? nullptr : &evaluator, o.common.seed);
  AttachPlacements(modeling, cell.place.X_BinPlace, params.placement, &plan);

  fmt::print("{}, profile {}, seed {}\n", source, o.common.profile, o.common.seed);
  fmt::print("modeling {:.3f} s: {} tubes; planning {:.3f} s: {} plans{}{}\n", modeling.total_seconds,
             modeling.tubes.size(), plan.total_seconds, plan.plans.size(),
             plan.used_simulation ? " (trajectories simulated)" : "", plan.bin_empty ? "; BIN EMPTY" : "");
  fmt::print("{:>5} {:>9} {:>9}\n", "tube", "length_m", "occlusion");
  for (const Tube& t : plan.tubes)
    fmt::print("{:>5} {:>9.3f} {:>9}\n", t.id, t.length(), OcclusionName(t.occlusion));
  fmt::print("{:>4} {:>5} {:>17} {:>26} {:>7} {:>7} {:>7} {:>7} {:>9}\n", "rank", "tube", "trajectory",
             "grasp (x, y, z) m", "H", "C", "T", "G", "disp_m");
  for (std::size_t i = 0; i < plan.plans.size() && i < o.show; ++i) {
    const PickPlan& p = plan.plans[i];
    const Eigen::Vector3d g = p.grasp.p_Bin_grasp;
    fmt::print("{:>4} {:>5} {:>17} ({:+.3f}, {:+.3f}, {:+.3f}) {:>7.3f} {:>7.3f} {:>7.3f} {:>7.3f} {:>9}\n",
               i, p.tube_id, ToString(p.kind), g.x(), g.y(), g.z(), p.costs.height, p.costs.centre,
               p.costs.trajectory, p.costs.total,
               p.displacement ? fmt::format("{:.4f}", *p.displacement) : "-");
  }
  if (!o.json_path.empty()) {
    WriteTextFile(o.json_path, ToJson(ToPlanPickResponse(plan, modeling, o.common.profile, o.common.seed)));
    fmt::print("wrote {}\n", o.json_path);
  }
}

}  // namespace

void AddPlanCommand(CLI::App& app) {
  auto o = std::make_shared<PlanOptions>();
  CLI::App* cmd = app.add_subcommand("plan", "Plan ranked picks for a cloud (thesis chapter 5)");
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
  cmd->add_option("--json", o->json_path, "Write the PlanPickResponse as proto3 JSON");
  cmd->add_option("--tubes", o->builtin_tubes, "Tubes in the built-in scene")
      ->check(CLI::Range(1, 30))
      ->capture_default_str();
  cmd->add_flag("--no-sim", o->no_sim, "Never simulate trajectories (occluded tubes get T = 0)");
  cmd->add_option("--sim-threads", o->sim_threads, "Simulation worker threads (0 = all cores)")
      ->capture_default_str();
  cmd->add_option("--show", o->show, "Plans to print")->capture_default_str();
  cmd->callback([o] { Run(*o); });
}

}  // namespace tubepick::cli
