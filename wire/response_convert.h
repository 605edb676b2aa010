#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"
#include "core/wrench/held_count.h"
#include "core/wrench/resolution_rotation.h"
#include "tubepick/v1/modeling.pb.h"
#include "tubepick/v1/planning.pb.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick {

/// The response of ModelTubes for a modeling result.
v1::ModelTubesResponse ToModelTubesResponse(const ModelingResult& result, const std::string& profile,
                                            std::uint64_t seed);

/// The response of PlanPick: plans best first, classified tubes, the modeling summary.
v1::PlanPickResponse ToPlanPickResponse(const PickPlanResult& plan, const ModelingResult& modeling,
                                        const std::string& profile, std::uint64_t seed);

/// The response of AnalyzeWrench: Algorithm 3's count and, for kMultiple, the horizontal torque
/// change and the resolution motions (`resolution` is PlanResolutionRotation's answer; std::nullopt
/// or an outcome other than kMultiple leaves the motions empty). `delta_torque_Tcp` is ΔM with its
/// vertical part removed; it is written only for kMultiple.
v1::AnalyzeWrenchResponse ToAnalyzeWrenchResponse(const HeldCount& count,
                                                  const std::optional<ResolutionPlan>& resolution,
                                                  const Eigen::Vector3d& delta_torque_Tcp);

}  // namespace tubepick
