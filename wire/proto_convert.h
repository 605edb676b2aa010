#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <google/protobuf/message.h>
#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "core/planning/trajectory.h"
#include "core/wrench/held_count.h"
#include "core/wrench/resolution_rotation.h"
#include "core/wrench/wrench.h"
#include "tubepick/v1/modeling.pb.h"
#include "tubepick/v1/planning.pb.h"
#include "tubepick/v1/requests.pb.h"
#include "tubepick/v1/types.pb.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick {

/// core ↔ wire (tubepick.v1) conversions of values, shared by the server and every client so all
/// of them see one schema. Whole responses: wire/response_convert.h.

v1::Vector3 ToProto(const Eigen::Vector3d& v);
v1::Pose ToProto(const Eigen::Isometry3d& X);
v1::Tube ToProto(const Tube& tube);
v1::Wrench ToProto(const Wrench& wrench);
v1::LengthUnit ToProto(LengthUnit unit);
v1::Occlusion ToProto(Occlusion occlusion);
v1::TrajectoryKind ToProto(TrajectoryKind kind);
v1::HeldOutcome ToProto(HeldOutcome outcome);
v1::ResolutionVariant ToProto(ResolutionVariant variant);
v1::ResolutionMotion ToProto(const ResolutionMotion& motion);

/// The vector as it is (for values this project wrote, e.g. a plan's waypoints).
Eigen::Vector3d FromProto(const v1::Vector3& v);
/// The vector of a caller's field. @throws InvalidArgument naming `field`.x/.y/.z when not finite.
Eigen::Vector3d FromProto(const v1::Vector3& v, const std::string& field);
/// The rigid transform of a wire pose: a finite position and a unit quaternion within 1e-3 (then
/// normalised). @throws InvalidArgument naming `field`.position.x ... or `field`.orientation, with
/// the values (a zero quaternion: "an absent orientation is all zeros").
Eigen::Isometry3d FromProto(const v1::Pose& pose, const std::string& field);
/// The core variant of a wire value; std::nullopt for RESOLUTION_VARIANT_UNSPECIFIED and for
/// numbers the enum does not define (proto3 enums are open).
std::optional<ResolutionVariant> FromProto(v1::ResolutionVariant variant);
/// The wire value of a cell's tube topology, and back: std::nullopt for TUBE_TOPOLOGY_UNSPECIFIED
/// and for numbers the enum does not define.
v1::TubeTopology ToProto(TubeTopology topology);
std::optional<TubeTopology> FromProto(v1::TubeTopology topology);
/// The wire value of a cell's junction shape, and back: std::nullopt for
/// JUNCTION_SHAPE_UNSPECIFIED and for numbers the enum does not define.
v1::JunctionShape ToProto(JunctionShape shape);
std::optional<JunctionShape> FromProto(v1::JunctionShape shape);

/// The CellDescription of `cell` with the sensor pose of the capture (X_BinSensor).
v1::CellDescription ToCellDescription(const CellConfig& cell, const Eigen::Isometry3d& X_BinSensor);

/// "upward", "escape", "occlusion_escape", "unspecified" (records and tables).
std::string TrajectoryKindName(v1::TrajectoryKind kind);
/// "sure", "simulated", "unsure", "unspecified" (records and tables).
std::string CertaintyName(v1::PlanCertainty certainty);
/// "none", "single", "multiple", "unspecified".
std::string HeldOutcomeName(v1::HeldOutcome outcome);

/// Proto3 JSON (field names as in the .proto, i.e. lowerCamelCase, enums by name).
std::string ToJson(const google::protobuf::Message& message, bool pretty = true);
/// Parses proto3 JSON into `message` (unknown fields are errors).
/// @throws InvalidArgument naming `what` and the parser's reason.
void FromJson(std::string_view json, google::protobuf::Message* message, const std::string& what);

}  // namespace tubepick
