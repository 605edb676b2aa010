#include "server/planning_jobs.h"

#include <memory>
#include <optional>

#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"
#include "core/planning/plan_placement.h"
#include "core/wrench/held_count.h"
#include "core/wrench/resolution_rotation.h"
#include "physics/trajectory_simulator.h"
#include "server/proto_convert.h"

namespace tubepick::server {
namespace {

ModelingResult Model(const PlanningJob& job, const StopToken* stop) {
  ThrowIfStopped(stop, "request admission");
  ModelingInput input;
  input.points_Sensor = &job.points_Sensor;
  input.unit = job.unit;
  input.X_BinSensor = job.cell.sensor.X_BinSensor;
  input.bin = job.cell.bin;
  input.seed = job.seed;
  return ModelTubes(input, job.params.modeling, stop);
}

}  // namespace

v1::ModelTubesResponse RunModelTubes(const PlanningJob& job, const StopToken* stop) {
  return ToModelTubesResponse(Model(job, stop), job.profile, job.seed);
}

v1::PlanPickResponse RunPlanPick(const PlanningJob& job, const PlanningDefaults& defaults,
                                 int simulation_threads, const StopToken* stop) {
  const ModelingResult modeling = Model(job, stop);

  std::unique_ptr<physics::BulletTrajectoryEvaluator> evaluator;
  if (!job.disable_simulation) {
    physics::TrajectorySimParams sim = defaults.simulation;
    sim.bin = job.cell.bin;
    sim.tube_mass = job.cell.tube.mass;
    sim.disp_max = job.params.planning.cost.max_displacement;
    sim.threads = simulation_threads;
    evaluator = std::make_unique<physics::BulletTrajectoryEvaluator>(sim);
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
    const Eigen::Vector3d up = job.params.up_Tcp.normalized();
    const Eigen::Vector3d delta = job.current.torque - job.reference.torque;
    delta_torque_Tcp = delta - delta.dot(up) * up;  // Eq. 5.7, as PlanResolutionRotation does
    resolution = PlanResolutionRotation(job.reference, job.current, job.X_BinTcp, job.params);
  }
  return ToAnalyzeWrenchResponse(count, resolution, delta_torque_Tcp);
}

}  // namespace tubepick::server
