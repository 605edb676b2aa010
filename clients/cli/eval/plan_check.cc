#include "clients/cli/eval/plan_check.h"

#include <limits>

#include "core/common/tube_graph.h"
#include "core/evaluation/virtual_labelling.h"
#include "physics/trajectory_simulator.h"

namespace tubepick::cli {
namespace {

double DistanceToAxis(const Eigen::Vector3d& p, const Tube& tube) {
  double best = std::numeric_limits<double>::infinity();
  for (const AxisPiece& piece : TubeAxisPieces(tube))
    best = std::min(best, DistanceToSegment(p, piece.a, piece.b));
  return best;
}

}  // namespace

PlanCheck CheckBestPlan(const PickPlanResult& plan, const std::vector<physics::TubeGeometry>& tubes_Bin,
                        const CellConfig& cell, const PlanningParams& params) {
  PlanCheck check;
  std::vector<Tube> real;
  for (std::size_t j = 0; j < tubes_Bin.size(); ++j) {
    real.push_back(tubes_Bin[j].ToTube());
    real.back().id = static_cast<std::uint32_t>(j);
  }
  std::vector<bool> free(real.size());
  for (std::size_t j = 0; j < real.size(); ++j) {
    free[j] = TubesLyingOn(real, j, params.certainty).empty();
    check.free_real_tubes += free[j] ? 1 : 0;
  }
  if (plan.plans.empty()) return check;
  const PickPlan& best = plan.plans.front();
  check.planned = true;
  check.certainty = ToString(best.certainty);
  check.trajectory = ToString(best.kind);
  for (const Tube& t : plan.tubes) {
    if (t.id == best.tube_id) check.modeled_class = ToString(t.occlusion);
  }

  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < real.size(); ++j) {
    const double d = DistanceToAxis(best.grasp.p_Bin_grasp, real[j]);
    if (d < nearest) {
      nearest = d;
      check.real_tube = static_cast<std::int32_t>(j);
    }
  }
  check.grasp_offset = nearest;
  if (check.real_tube < 0 || nearest > 2.0 * cell.tube.radius) {
    check.real_tube = -1;
    return check;
  }
  check.real_tube_free = free[static_cast<std::size_t>(check.real_tube)];

  const physics::TrajectorySimParams sim =
      physics::SimParamsForCell({}, cell, /*disp_max=*/100.0, /*threads=*/1);  // never stop early
  const physics::SettledTubes settled(real, sim, nullptr);
  Trajectory trajectory;
  trajectory.tube_index = static_cast<std::uint32_t>(check.real_tube);
  trajectory.kind = best.kind;
  trajectory.waypoints = best.waypoints;
  const physics::TrajectoryRun run = settled.Run(trajectory, nullptr);
  const double lift = best.waypoints.back().z();
  for (std::size_t j = 0; j < real.size(); ++j) {
    if (run.max_com_z[j] - settled.p_BinCo(j).z() > 0.5 * lift) ++check.lifted;
  }
  check.displacement = run.outcome.displacement;
  return check;
}

PlanCheckSummary SummarizePlanChecks(const std::vector<const PlanCheck*>& checks) {
  PlanCheckSummary s;
  for (const PlanCheck* c : checks) {
    ++s.scenes;
    if (!c->planned) continue;
    ++s.planned;
    s.sure += c->certainty == "sure";
    s.simulated += c->certainty == "simulated";
    s.unsure += c->certainty == "unsure";
    if (c->real_tube < 0) {
      ++s.off_tube;
      continue;
    }
    s.grasped_free += c->real_tube_free;
    s.grasped_lain_on_while_free += !c->real_tube_free && c->free_real_tubes > 0;
    s.lifted_alone += c->lifted == 1;
    s.lifted_several += c->lifted > 1;
    s.lifted_none += c->lifted == 0;
  }
  return s;
}

}  // namespace tubepick::cli
