#include "server/planning_jobs.h"

#include <chrono>
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

// raw_region_Bin: the raw points the caller needs kept (ModelingInput::raw_region_Bin).
ModelingResult Model(const PlanningJob& job, const RawRegion& raw_region_Bin, std::uint32_t threads,
                     const StopToken* stop) {
  ThrowIfStopped(stop, "request admission");
  ModelingInput input = ModelingInputFor(job.cell);
  input.xyz_Sensor = PackedXyz{job.xyz_Sensor};
  input.raw_region_Bin = raw_region_Bin;
  input.unit = job.unit;
  input.seed = job.seed;
  ModelingParams params = job.params.modeling;
  params.threads = threads;
  return ModelTubes(input, params, stop);
}

}  // namespace

v1::ModelTubesResponse RunModelTubes(const PlanningJob& job, std::uint32_t threads, const StopToken* stop) {
  return ToModelTubesResponse(Model(job, RawRegion::None(), threads, stop), job.profile, job.seed);
}

v1::PlanPickResponse RunPlanPick(const PlanningJob& job, const PlanningDefaults& defaults,
                                 std::uint32_t threads, const StopToken* stop) {
  const ModelingResult modeling =
      Model(job, RawRegionForPlanning(job.params.planning, job.cell.bin), threads, stop);

  std::unique_ptr<physics::BulletTrajectoryEvaluator> evaluator;
  if (!job.disable_simulation) {
    evaluator = std::make_unique<physics::BulletTrajectoryEvaluator>(physics::SimParamsForCell(
        defaults.simulation, job.cell, job.params.planning.cost.max_displacement, static_cast<int>(threads)));
  }
  PickPlanResult plan = PlanPick(modeling, job.cell, job.params.planning, evaluator.get(), job.seed, stop);
  // Truncate first: placements are computed only for the plans that are sent.
  if (job.max_plans > 0 && plan.plans.size() > job.max_plans) plan.plans.resize(job.max_plans);
  using Clock = std::chrono::steady_clock;
  const auto seconds_since = [](Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  Clock::time_point t0 = Clock::now();
  AttachPlacements(modeling, job.cell.place.X_BinPlace, job.params.placement, &plan);
  plan.timings.push_back({"placement", seconds_since(t0)});
  t0 = Clock::now();
  v1::PlanPickResponse response = ToPlanPickResponse(plan, modeling, job.profile, job.seed);
  v1::StageTiming* timing = response.add_stage_timings();
  timing->set_stage("response");  // building this message (gRPC then serializes it)
  timing->set_seconds(seconds_since(t0));
  return response;
}

}  // namespace tubepick::server
