#include "wire/proto_convert.h"

#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/tube_graph.h"

namespace tubepick {
namespace {

// Largest |‖q‖ − 1| of a quaternion accepted (and then normalised).
constexpr double kQuaternionTol = 1e-3;

// A unit quaternion within kQuaternionTol, normalised; a zero or far-from-unit quaternion is an error.
Eigen::Quaterniond FromProto(const v1::Quaternion& q, const std::string& field) {
  RequireFiniteField(q.x(), field + ".x");
  RequireFiniteField(q.y(), field + ".y");
  RequireFiniteField(q.z(), field + ".z");
  RequireFiniteField(q.w(), field + ".w");
  const Eigen::Quaterniond rotation(q.w(), q.x(), q.y(), q.z());
  const double norm = rotation.norm();
  if (!(std::abs(norm - 1.0) <= kQuaternionTol)) {
    throw InvalidArgument(field + ": quaternion (x, y, z, w) = (" + FormatNumber(q.x()) + ", " +
                          FormatNumber(q.y()) + ", " + FormatNumber(q.z()) + ", " + FormatNumber(q.w()) +
                          ") is not unit length: |q| = " + FormatNumber(norm) + " (tolerance 1e-3)" +
                          (norm == 0.0 ? "; an absent orientation is all zeros" : ""));
  }
  return rotation.normalized();
}

}  // namespace

v1::Vector3 ToProto(const Eigen::Vector3d& v) {
  v1::Vector3 out;
  out.set_x(v.x());
  out.set_y(v.y());
  out.set_z(v.z());
  return out;
}

v1::Pose ToProto(const Eigen::Isometry3d& X) {
  v1::Pose out;
  *out.mutable_position() = ToProto(Eigen::Vector3d(X.translation()));
  const Eigen::Quaterniond q(X.linear());
  v1::Quaternion* o = out.mutable_orientation();
  o->set_x(q.x());
  o->set_y(q.y());
  o->set_z(q.z());
  o->set_w(q.w());
  return out;
}

v1::Tube ToProto(const Tube& tube) {
  v1::Tube out;
  out.set_id(tube.id);
  for (const Cylinder& c : tube.cylinders) {
    v1::Cylinder* pc = out.add_cylinders();
    *pc->mutable_start() = ToProto(c.start);
    *pc->mutable_end() = ToProto(c.end);
    pc->set_radius(c.radius);
    pc->set_segment_id(c.segment_id);
    pc->set_inlier_count(c.inlier_count);
  }
  out.set_length(tube.length());
  out.set_occlusion(ToProto(tube.occlusion));
  out.set_occluded_joint_count(tube.occluded_joint_count);
  for (const TubeNode& n : NodesOf(tube)) *out.add_nodes()->mutable_position() = ToProto(n.p_Bin);
  for (const TubeBranch& b : BranchesOf(tube)) {
    v1::TubeBranch* pb = out.add_branches();
    pb->set_from_node(b.from_node);
    pb->set_to_node(b.to_node);
    pb->set_first_cylinder(b.first_cylinder);
    pb->set_cylinder_count(b.cylinder_count);
  }
  return out;
}

v1::Wrench ToProto(const Wrench& wrench) {
  v1::Wrench out;
  *out.mutable_force() = ToProto(wrench.force);
  *out.mutable_torque() = ToProto(wrench.torque);
  return out;
}

v1::LengthUnit ToProto(LengthUnit unit) {
  return unit == LengthUnit::kMillimetre ? v1::LENGTH_UNIT_MILLIMETRE : v1::LENGTH_UNIT_METRE;
}

v1::Occlusion ToProto(Occlusion occlusion) {
  switch (occlusion) {
    case Occlusion::kNone:
      return v1::OCCLUSION_NONE;
    case Occlusion::kWeak:
      return v1::OCCLUSION_WEAK;
    case Occlusion::kStrong:
      return v1::OCCLUSION_STRONG;
    case Occlusion::kUnspecified:
      break;
  }
  return v1::OCCLUSION_UNSPECIFIED;
}

v1::TrajectoryKind ToProto(TrajectoryKind kind) {
  switch (kind) {
    case TrajectoryKind::kUpward:
      return v1::TRAJECTORY_KIND_UPWARD;
    case TrajectoryKind::kEscape:
      return v1::TRAJECTORY_KIND_ESCAPE;
    case TrajectoryKind::kOcclusionEscape:
      return v1::TRAJECTORY_KIND_OCCLUSION_ESCAPE;
  }
  return v1::TRAJECTORY_KIND_UNSPECIFIED;
}

v1::HeldOutcome ToProto(HeldOutcome outcome) {
  switch (outcome) {
    case HeldOutcome::kNone:
      return v1::HELD_OUTCOME_NONE;
    case HeldOutcome::kSingle:
      return v1::HELD_OUTCOME_SINGLE;
    case HeldOutcome::kMultiple:
      return v1::HELD_OUTCOME_MULTIPLE;
  }
  return v1::HELD_OUTCOME_UNSPECIFIED;
}

v1::ResolutionVariant ToProto(ResolutionVariant variant) {
  switch (variant) {
    case ResolutionVariant::kTorqueAxis:
      return v1::RESOLUTION_VARIANT_TORQUE_AXIS;
    case ResolutionVariant::kTorqueAxisNegative:
      return v1::RESOLUTION_VARIANT_TORQUE_AXIS_NEGATIVE;
    case ResolutionVariant::kPerpendicular:
      return v1::RESOLUTION_VARIANT_PERPENDICULAR;
    case ResolutionVariant::kJointSafe:
      return v1::RESOLUTION_VARIANT_JOINT_SAFE;
    case ResolutionVariant::kTorqueAxisThenPerpendicular:
      return v1::RESOLUTION_VARIANT_TORQUE_AXIS_THEN_PERPENDICULAR;
  }
  return v1::RESOLUTION_VARIANT_UNSPECIFIED;
}

v1::TubeTopology ToProto(TubeTopology topology) {
  switch (topology) {
    case TubeTopology::kLinear:
      return v1::TUBE_TOPOLOGY_LINEAR;
    case TubeTopology::kBranched:
      return v1::TUBE_TOPOLOGY_BRANCHED;
    case TubeTopology::kAuto:
      return v1::TUBE_TOPOLOGY_AUTO;
  }
  return v1::TUBE_TOPOLOGY_UNSPECIFIED;
}

std::optional<TubeTopology> FromProto(v1::TubeTopology topology) {
  switch (topology) {
    case v1::TUBE_TOPOLOGY_LINEAR:
      return TubeTopology::kLinear;
    case v1::TUBE_TOPOLOGY_BRANCHED:
      return TubeTopology::kBranched;
    case v1::TUBE_TOPOLOGY_AUTO:
      return TubeTopology::kAuto;
    default:
      return std::nullopt;
  }
}

v1::JunctionShape ToProto(JunctionShape shape) {
  switch (shape) {
    case JunctionShape::kAny:
      return v1::JUNCTION_SHAPE_ANY;
    case JunctionShape::kWye:
      return v1::JUNCTION_SHAPE_WYE;
    case JunctionShape::kTee:
      return v1::JUNCTION_SHAPE_TEE;
  }
  return v1::JUNCTION_SHAPE_UNSPECIFIED;
}

std::optional<JunctionShape> FromProto(v1::JunctionShape shape) {
  switch (shape) {
    case v1::JUNCTION_SHAPE_ANY:
      return JunctionShape::kAny;
    case v1::JUNCTION_SHAPE_WYE:
      return JunctionShape::kWye;
    case v1::JUNCTION_SHAPE_TEE:
      return JunctionShape::kTee;
    default:
      return std::nullopt;
  }
}

v1::ResolutionMotion ToProto(const ResolutionMotion& motion) {
  v1::ResolutionMotion out;
  *out.mutable_axis_tcp() = ToProto(motion.axis_Tcp);
  out.set_angle(motion.angle);
  out.set_yaw(motion.yaw);
  for (const ResolutionWaypoint& w : motion.waypoints) {
    v1::ResolutionWaypoint* pw = out.add_waypoints();
    *pw->mutable_tcp_pose() = ToProto(w.X_BinTcpRotated);
    pw->set_description(w.description);
  }
  out.set_description(motion.description);
  return out;
}

Eigen::Vector3d FromProto(const v1::Vector3& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Vector3d FromProto(const v1::Vector3& v, const std::string& field) {
  RequireFiniteField(v.x(), field + ".x");
  RequireFiniteField(v.y(), field + ".y");
  RequireFiniteField(v.z(), field + ".z");
  return {v.x(), v.y(), v.z()};
}

Eigen::Isometry3d FromProto(const v1::Pose& pose, const std::string& field) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = FromProto(pose.position(), field + ".position");
  X.linear() = FromProto(pose.orientation(), field + ".orientation").toRotationMatrix();
  return X;
}

std::optional<ResolutionVariant> FromProto(v1::ResolutionVariant variant) {
  switch (static_cast<int>(variant)) {
    case v1::RESOLUTION_VARIANT_TORQUE_AXIS:
      return ResolutionVariant::kTorqueAxis;
    case v1::RESOLUTION_VARIANT_TORQUE_AXIS_NEGATIVE:
      return ResolutionVariant::kTorqueAxisNegative;
    case v1::RESOLUTION_VARIANT_PERPENDICULAR:
      return ResolutionVariant::kPerpendicular;
    case v1::RESOLUTION_VARIANT_JOINT_SAFE:
      return ResolutionVariant::kJointSafe;
    case v1::RESOLUTION_VARIANT_TORQUE_AXIS_THEN_PERPENDICULAR:
      return ResolutionVariant::kTorqueAxisThenPerpendicular;
    default:
      return std::nullopt;
  }
}

v1::CellDescription ToCellDescription(const CellConfig& cell, const Eigen::Isometry3d& X_BinSensor) {
  v1::CellDescription out;
  *out.mutable_bin_inner_size() = ToProto(cell.bin.inner_size);
  *out.mutable_sensor_pose() = ToProto(X_BinSensor);
  out.set_tube_radius(cell.tube.radius);
  out.set_tube_length(cell.tube.length);
  out.set_tube_mass(cell.tube.mass);
  out.set_tube_topology(ToProto(cell.tube.topology));
  out.set_tube_junction_shape(ToProto(cell.tube.junction_shape));
  out.set_tube_junctions(cell.tube.layout.junctions);
  out.set_tube_junction_spacing(cell.tube.layout.junction_spacing);
  out.set_tube_branch_length(cell.tube.layout.branch_length);
  *out.mutable_place_pose() = ToProto(cell.place.X_BinPlace);
  return out;
}

std::string TrajectoryKindName(v1::TrajectoryKind kind) {
  switch (kind) {
    case v1::TRAJECTORY_KIND_UPWARD:
      return "upward";
    case v1::TRAJECTORY_KIND_ESCAPE:
      return "escape";
    case v1::TRAJECTORY_KIND_OCCLUSION_ESCAPE:
      return "occlusion_escape";
    default:
      break;
  }
  return "unspecified";
}

std::string CertaintyName(v1::PlanCertainty certainty) {
  switch (certainty) {
    case v1::PLAN_CERTAINTY_SURE:
      return "sure";
    case v1::PLAN_CERTAINTY_SIMULATED:
      return "simulated";
    case v1::PLAN_CERTAINTY_UNSURE:
      return "unsure";
    default:
      break;
  }
  return "unspecified";
}

std::string HeldOutcomeName(v1::HeldOutcome outcome) {
  switch (outcome) {
    case v1::HELD_OUTCOME_NONE:
      return "none";
    case v1::HELD_OUTCOME_SINGLE:
      return "single";
    case v1::HELD_OUTCOME_MULTIPLE:
      return "multiple";
    default:
      break;
  }
  return "unspecified";
}

std::string ToJson(const google::protobuf::Message& message, bool pretty) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = pretty;
  options.preserve_proto_field_names = false;
  options.always_print_primitive_fields = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(message, &json, options);
  if (!status.ok()) throw std::runtime_error("JSON conversion failed: " + std::string(status.message()));
  return json;
}

}  // namespace tubepick

namespace tubepick {

void FromJson(std::string_view json, google::protobuf::Message* message, const std::string& what) {
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  const auto status = google::protobuf::util::JsonStringToMessage(
      google::protobuf::StringPiece(json.data(), json.size()), message, options);
  if (!status.ok()) {
    throw InvalidArgument(fmt::format("{} is not a {} in proto3 JSON: {}", what,
                                      message->GetDescriptor()->name(), std::string(status.message())));
  }
}

}  // namespace tubepick
