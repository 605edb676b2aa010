#pragma once

#include "core/modeling/model_tubes.h"
#include "core/placement/placement.h"
#include "core/planning/pick_planner.h"

namespace tubepick {

/// Attaches to every plan the TCP pose that lays its tube on the cell's placement frame
/// (thesis §5.2.7): the PCA frame of the tube's points in the filtered cloud (its tube model's
/// axes when it has fewer than 10 points), composed with the plan's grasp. Plans whose tube has
/// no defined yaw (nearly vertical) keep no placement pose.
void AttachPlacements(const ModelingResult& modeling, const Eigen::Isometry3d& X_BinPlace,
                      const PlacementParams& params, PickPlanResult* result);

}  // namespace tubepick
