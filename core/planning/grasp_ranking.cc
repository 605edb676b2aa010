#include "core/planning/grasp_ranking.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <tuple>

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

double TrajectoryCost(std::optional<double> displacement, double max_displacement) {
  if (!displacement) return 0.0;
  assert(max_displacement > 0.0);
  return std::clamp(*displacement, 0.0, max_displacement) / max_displacement;
}

PlanCosts PlanCost(double grasp_z, double max_z, double curve_position, double tube_length,
                   std::optional<double> displacement, const CostParams& params) {
  PlanCosts costs;
  costs.height = HeightCost(grasp_z, max_z);
  costs.centre = CentreCost(curve_position, tube_length);
  costs.trajectory = TrajectoryCost(displacement, params.max_displacement);
  costs.total = params.height_weight * costs.height + params.centre_weight * costs.centre +
                params.trajectory_weight * costs.trajectory;
  return costs;
}

bool PlanBefore(const PickPlan& a, const PickPlan& b) {
  return std::forward_as_tuple(a.costs.total, a.tube_id, a.trajectory_index, a.grasp.curve_position,
                               a.grasp.cylinder_index) <
         std::forward_as_tuple(b.costs.total, b.tube_id, b.trajectory_index, b.grasp.curve_position,
                               b.grasp.cylinder_index);
}

void RankPlans(std::vector<PickPlan>* plans) {
  assert(plans != nullptr);
  std::stable_sort(plans->begin(), plans->end(), PlanBefore);
}

}  // namespace tubepick
