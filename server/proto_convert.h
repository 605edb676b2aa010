#pragma once

#include <optional>
#include <string>

#include <google/protobuf/message.h>

#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"
#include "core/wrench/held_count.h"
#include "core/wrench/resolution_rotation.h"
#include "tubepick/v1/modeling.pb.h"
#include "tubepick/v1/planning.pb.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick {

/// core → wire conversions (the server owns the proto ↔ core mapping; the CLI reuses it so
/// every consumer sees one schema).
void ToProto(const Eigen::Vector3d& v, v1::Vector3* out);
void ToProto(const Eigen::Isometry3d& X, v1::Pose* out);
void ToProto(const Tube& tube, v1::Tube* out);
v1::Occlusion ToProto(Occlusion occlusion);

/// The response of ModelTubes for a modeling result.
v1::ModelTubesResponse ToModelTubesResponse(const ModelingResult& result, const std::string& profile,
                                            std::uint64_t seed);

v1::TrajectoryKind ToProto(TrajectoryKind kind);

/// The response of PlanPick: plans best first, classified tubes, the modeling summary.
v1::PlanPickResponse ToPlanPickResponse(const PickPlanResult& plan, const ModelingResult& modeling,
                                        const std::string& profile, std::uint64_t seed);

v1::HeldOutcome ToProto(HeldOutcome outcome);
v1::ResolutionVariant ToProto(ResolutionVariant variant);
/// The core variant of a wire value; std::nullopt for RESOLUTION_VARIANT_UNSPECIFIED and for
/// numbers the enum does not define (proto3 enums are open).
std::optional<ResolutionVariant> FromProto(v1::ResolutionVariant variant);
void ToProto(const ResolutionMotion& motion, v1::ResolutionMotion* out);

/// The response of AnalyzeWrench: Algorithm 3's count and, for kMultiple, the horizontal torque
/// change and the resolution motions (`resolution` is PlanResolutionRotation's answer; std::nullopt
/// or an outcome other than kMultiple leaves the motions empty). `delta_torque_Tcp` is ΔM with its
/// vertical part removed; it is written only for kMultiple.
v1::AnalyzeWrenchResponse ToAnalyzeWrenchResponse(const HeldCount& count,
                                                  const std::optional<ResolutionPlan>& resolution,
                                                  const Eigen::Vector3d& delta_torque_Tcp);

/// Proto3 JSON (field names as in the .proto, i.e. lowerCamelCase, enums by name).
std::string ToJson(const google::protobuf::Message& message, bool pretty = true);

}  // namespace tubepick
