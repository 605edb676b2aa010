#include "clients/cli/local/plan_command.h"

#include <fmt/core.h>

#include <memory>

#include "clients/cli/inputs/cli_inputs.h"
#include "core/common/tube_graph.h"
#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"
#include "core/planning/plan_placement.h"
#include "physics/trajectory_simulator.h"
#include "wire/proto_convert.h"
#include "wire/response_convert.h"

namespace tubepick::cli {
namespace {

struct PlanOptions {
  InputOptions input;
  std::string json_path;
  bool no_sim = false;
  std::uint32_t sim_threads = 0;
  std::uint32_t show = 5;
};

void Run(const PlanOptions& o) {
  const CommonOptions& common = o.input.common;
  const CellConfig cell = LoadCell(common);
  const Params params = LoadParamsFor(common);
  const CloudInput cloud = LoadCloudInput(o.input, cell);
  const InProcessPlan planned = PlanInProcess(cloud, cell, params, common.seed, o.no_sim, o.sim_threads);
  const ModelingResult& modeling = planned.modeling;
  const PickPlanResult& plan = planned.plan;

  fmt::print("{}, profile {}, seed {}\n", cloud.source, common.profile, common.seed);
  fmt::print("modeling {:.3f} s: {} tubes; planning {:.3f} s: {} plans{}{}\n", modeling.total_seconds,
             modeling.tubes.size(), plan.total_seconds, plan.plans.size(),
             plan.used_simulation ? " (trajectories simulated)" : "", plan.bin_empty ? "; BIN EMPTY" : "");
  fmt::print("{:>5} {:>9} {:>8} {:>9}  {}\n", "tube", "length_m", "branches", "occlusion", "lain on by");
  for (std::size_t i = 0; i < plan.tubes.size(); ++i) {
    const Tube& t = plan.tubes[i];
    std::string lain_on;
    for (std::uint32_t u : plan.classes[i].lying_on) lain_on += fmt::format("{} ", plan.tubes[u].id);
    fmt::print("{:>5} {:>9.3f} {:>8} {:>9}  {}\n", t.id, t.length(), BranchesOf(t).size(),
               ToString(t.occlusion), lain_on.empty() ? "-" : lain_on);
  }
  fmt::print("{:>4} {:>5} {:>17} {:>9} {:>26} {:>7} {:>7} {:>7} {:>7} {:>9}\n", "rank", "tube", "trajectory",
             "certainty", "grasp (x, y, z) m", "H", "C", "T", "G", "disp_m");
  for (std::size_t i = 0; i < plan.plans.size() && i < o.show; ++i) {
    const PickPlan& p = plan.plans[i];
    const Eigen::Vector3d g = p.grasp.p_Bin_grasp;
    fmt::print(
        "{:>4} {:>5} {:>17} {:>9} ({:+.3f}, {:+.3f}, {:+.3f}) {:>7.3f} {:>7.3f} {:>7.3f} {:>7.3f} {:>9}\n", i,
        p.tube_id, ToString(p.kind), ToString(p.certainty), g.x(), g.y(), g.z(), p.costs.height,
        p.costs.centre, p.costs.trajectory, p.costs.total,
        p.displacement ? fmt::format("{:.4f}", *p.displacement) : "-");
  }
  if (!o.json_path.empty()) {
    WriteTextFile(o.json_path, ToJson(ToPlanPickResponse(plan, modeling, common.profile, common.seed)));
    fmt::print("wrote {}\n", o.json_path);
  }
}

}  // namespace

InProcessPlan PlanInProcess(const CloudInput& cloud, const CellConfig& cell, const Params& params,
                            std::uint64_t seed, bool no_sim, std::uint32_t sim_threads) {
  const ModelingInput input = MakeModelingInput(cloud.points_Sensor, cloud.unit, cell, seed,
                                                RawRegionForPlanning(params.planning, cell.bin));
  InProcessPlan out{ModelTubes(input, params.modeling), {}};
  physics::BulletTrajectoryEvaluator evaluator(physics::SimParamsForCell(
      {}, cell, params.planning.cost.max_displacement, static_cast<int>(sim_threads)));
  out.plan = PlanPick(out.modeling, cell, params.planning, no_sim ? nullptr : &evaluator, seed);
  AttachPlacements(out.modeling, cell.place.X_BinPlace, params.placement, &out.plan);
  return out;
}

void AddPlanCommand(CLI::App& app) {
  auto o = std::make_shared<PlanOptions>();
  CLI::App* cmd = app.add_subcommand("plan", "Plan ranked picks for a cloud (thesis chapter 5)");
  AddInputOptions(cmd, o->input);
  cmd->add_option("--json", o->json_path, "Write the PlanPickResponse as proto3 JSON");
  cmd->add_flag("--no-sim", o->no_sim, "Never simulate trajectories (occluded tubes get T = 0)");
  cmd->add_option("--sim-threads", o->sim_threads, "Simulation worker threads (0 = all cores)")
      ->capture_default_str();
  cmd->add_option("--show", o->show, "Plans to print")->capture_default_str();
  cmd->callback([o] { Run(*o); });
}

}  // namespace tubepick::cli
