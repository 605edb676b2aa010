#include "core/planning/plan_placement.h"

#include <map>
#include <optional>

namespace tubepick {

void AttachPlacements(const ModelingResult& modeling, const Eigen::Isometry3d& X_BinPlace,
                      const PlacementParams& params, PickPlanResult* result) {
  constexpr std::size_t kMinPoints = 10;
  // One frame per tube: every plan of a tube shares it.
  std::map<std::uint32_t, std::optional<TubeFrame>> frames;
  for (PickPlan& plan : result->plans) {
    auto it = frames.find(plan.tube_id);
    if (it == frames.end()) {
      Points points_Bin;
      for (std::size_t i = 0; i < modeling.tube_of_point.size(); ++i) {
        if (modeling.tube_of_point[i] == static_cast<std::int32_t>(plan.tube_id)) {
          points_Bin.push_back(modeling.filtered.points[i]);
        }
      }
      std::optional<TubeFrame> frame;
      if (points_Bin.size() >= kMinPoints) {
        frame = EstimateTubeFrame(points_Bin, params, plan.grasp.p_Bin_grasp);
      } else {
        for (const Tube& tube : result->tubes) {
          if (tube.id == plan.tube_id) frame = EstimateTubeFrame(tube, params, plan.grasp.p_Bin_grasp);
        }
      }
      it = frames.emplace(plan.tube_id, frame).first;
    }
    if (it->second)
      plan.X_BinTcp_place = PlanPlacement(plan.grasp.X_BinTcp, *it->second, X_BinPlace, params).X_BinTcpPlace;
  }
}

}  // namespace tubepick
