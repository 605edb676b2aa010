#include "core/planning/grasp_ranking.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <tuple>

#include "core/common/tube_graph.h"

namespace tubepick {

double HeightCost(double grasp_z, double max_z) {
  if (!(max_z > 0.0)) return 0.0;
  return std::clamp(grasp_z / max_z, 0.0, 1.0);
}

double CentreCost(double curve_position, double tube_length) {
  if (!(tube_length > 0.0)) return 0.0;
  const double half = 0.5 * tube_length;
  return std::clamp(std::abs(curve_position - half) / half, 0.0, 1.0);
}

double MassCentreCost(const Eigen::Vector3d& p_Bin_grasp, const Tube& tube) {
  const Eigen::Vector3d centre = TubeMassCentre(tube);
  double reach = 0.0;
  for (const Cylinder& c : tube.cylinders) {
    reach = std::max({reach, (c.start - centre).norm(), (c.end - centre).norm()});
  }
  if (!(reach > 0.0)) return 0.0;
  return std::clamp((p_Bin_grasp - centre).norm() / reach, 0.0, 1.0);
}

double GraspCentreCost(const Grasp& grasp, const Tube& tube) {
  return BranchesOf(tube).size() > 1 ? MassCentreCost(grasp.p_Bin_grasp, tube)
                                     : CentreCost(grasp.curve_position, tube.length());
}

double TrajectoryCost(std::optional<double> displacement, double max_displacement) {
  if (!displacement) return 0.0;
  assert(max_displacement > 0.0);
  return std::clamp(*displacement, 0.0, max_displacement) / max_displacement;
}

namespace {

PlanCosts Weighted(double height, double centre, double trajectory, const CostParams& params) {
  PlanCosts costs;
  costs.height = height;
  costs.centre = centre;
  costs.trajectory = trajectory;
  costs.total = params.height_weight * costs.height + params.centre_weight * costs.centre +
                params.trajectory_weight * costs.trajectory;
  return costs;
}

}  // namespace

PlanCosts PlanCost(double grasp_z, double max_z, double curve_position, double tube_length,
                   std::optional<double> displacement, const CostParams& params) {
  return Weighted(HeightCost(grasp_z, max_z), CentreCost(curve_position, tube_length),
                  TrajectoryCost(displacement, params.max_displacement), params);
}

PlanCosts PlanCost(const Grasp& grasp, const Tube& tube, double max_z, std::optional<double> displacement,
                   const CostParams& params) {
  return Weighted(HeightCost(grasp.p_Bin_grasp.z(), max_z), GraspCentreCost(grasp, tube),
                  TrajectoryCost(displacement, params.max_displacement), params);
}

bool PlanIsSafe(const PickPlan& plan, const CertaintyParams& params) {
  switch (plan.certainty) {
    case PlanCertainty::kSure:
      return true;
    case PlanCertainty::kSimulated:
      return plan.displacement && *plan.displacement <= params.safe_displacement;
    case PlanCertainty::kUnsure:
      return false;
  }
  return false;
}

bool PlanBefore(const PickPlan& a, const PickPlan& b, const CertaintyParams& params) {
  const bool a_unsafe = params.safe_first && !PlanIsSafe(a, params);
  const bool b_unsafe = params.safe_first && !PlanIsSafe(b, params);
  return std::forward_as_tuple(a_unsafe, a.costs.total, a.tube_id, a.trajectory_index, a.grasp.curve_position,
                               a.grasp.cylinder_index) <
         std::forward_as_tuple(b_unsafe, b.costs.total, b.tube_id, b.trajectory_index, b.grasp.curve_position,
                               b.grasp.cylinder_index);
}

void RankPlans(std::vector<PickPlan>* plans, const CertaintyParams& params) {
  assert(plans != nullptr);
  std::stable_sort(plans->begin(), plans->end(),
                   [&params](const PickPlan& a, const PickPlan& b) { return PlanBefore(a, b, params); });
}

}  // namespace tubepick
