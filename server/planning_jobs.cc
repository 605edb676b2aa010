#include "server/planning_jobs.h"

#include <memory>
#include <optional>

#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"
#include "core/planning/plan_placement.h"
#include "core/wrench/held_count.h"
#include "core/wrench/resolution_rotation.h"
#include "physics/trajectory_simulator.h"
#include "wire/response_convert.h"

namespace tubepick::server {
namespace {

ModelingResult Model(const PlanningJob& job, std::uint32_t threads, const StopToken* stop) {
  ThrowIfStopped(stop, "request admission");
  ModelingInput input;
  input.points_Sensor = &job.points_Sensor;
  input.unit = job.unit;
  input.X_BinSensor = job.cell.sensor.X_BinSensor;
  input.bin = job.cell.bin;
  input.seed = job.seed;
  ModelingParams params = job.params.modeling;
  params.threads = threads;
  return ModelTubes(input, params, stop);
}

}  // namespace

v1::ModelTubesResponse RunModelTubes(const PlanningJob& job, std::uint32_t threads, const StopToken* stop) {
  return ToModelTubesResponse(Model(job, threads, stop), job.profile, job.seed);
}

v1::PlanPickResponse RunPlanPick(const PlanningJob& job, const PlanningDefaults& defaults,
                                 std::uint32_t threads, const StopToken* stop) {
  const ModelingResult modeling = Model(job, threads, stop);

  std::unique_ptr<physics::BulletTrajectoryEvaluator> evaluator;
  if (!job.disable_simulation) {
    evaluator = std::make_unique<physics::BulletTrajectoryEvaluator>(physics::SimParamsForCell(
        defaults.simulation, job.cell, job.params.planning.cost.max_displacement, static_cast<int>(threads)));
  }
  PickPlanResult plan = PlanPick(modeling, job.cell, job.params.planning, evaluator.get(), job.seed, stop);
  // Truncate first: placements are computed only for the plans that are sent.
  if (job.max_plans > 0 && plan.plans.size() > job.max_plans) plan.plans.resize(job.max_plans);
  AttachPlacements(modeling, job.cell.place.X_BinPlace, job.params.placement, &plan);
  return ToPlanPickResponse(plan, modeling, job.profile, job.seed);
}

v1::AnalyzeWrenchResponse RunAnalyzeWrench(const WrenchJob& job) {
  const HeldCount count = CountHeldTubes(job.reference, job.current, job.tube_mass, job.params);
  std::optional<ResolutionPlan> resolution;
  Eigen::Vector3d delta_torque_Tcp = Eigen::Vector3d::Zero();
  if (count.outcome == HeldOutcome::kMultiple) {
    delta_torque_Tcp = HorizontalTorqueChange(job.reference, job.current, job.params.up_Tcp);
    resolution = PlanResolutionRotation(job.reference, job.current, job.X_BinTcp, job.params);
  }
  return ToAnalyzeWrenchResponse(count, resolution, delta_torque_Tcp);
}

}  // namespace tubepick::server
