#include "server/proto_convert.h"

#include <google/protobuf/util/json_util.h>

#include "core/common/errors.h"

namespace tubepick {

void ToProto(const Eigen::Vector3d& v, v1::Vector3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

void ToProto(const Eigen::Isometry3d& X, v1::Pose* out) {
  ToProto(Eigen::Vector3d(X.translation()), out->mutable_position());
  const Eigen::Quaterniond q(X.linear());
  out->mutable_orientation()->set_x(q.x());
  out->mutable_orientation()->set_y(q.y());
  out->mutable_orientation()->set_z(q.z());
  out->mutable_orientation()->set_w(q.w());
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

void ToProto(const Tube& tube, v1::Tube* out) {
  out->set_id(tube.id);
  for (const Cylinder& c : tube.cylinders) {
    v1::Cylinder* pc = out->add_cylinders();
    ToProto(c.start, pc->mutable_start());
    ToProto(c.end, pc->mutable_end());
    pc->set_radius(c.radius);
    pc->set_segment_id(c.segment_id);
    pc->set_inlier_count(c.inlier_count);
  }
  out->set_length(tube.length());
  out->set_occlusion(ToProto(tube.occlusion));
  out->set_occluded_joint_count(tube.occluded_joint_count);
}

v1::ModelTubesResponse ToModelTubesResponse(const ModelingResult& result, const std::string& profile,
                                            std::uint64_t seed) {
  v1::ModelTubesResponse response;
  for (const Tube& t : result.tubes) ToProto(t, response.add_tubes());
  response.set_max_height(result.max_height);
  response.set_input_points(result.input_points);
  response.set_dropped_non_finite(result.dropped_non_finite);
  response.set_segment_count(result.segment_count);
  response.set_cylinder_count(result.cylinder_count);
  for (const StepCount& c : result.counts) {
    v1::StepCount* pc = response.add_step_counts();
    pc->set_step(c.step);
    pc->set_points(c.points);
  }
  for (const StageTiming& t : result.timings) {
    v1::StageTiming* pt = response.add_stage_timings();
    pt->set_stage(t.stage);
    pt->set_seconds(t.seconds);
  }
  response.set_total_seconds(result.total_seconds);
  response.set_profile(profile);
  response.set_seed(seed);
  return response;
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

v1::PlanPickResponse ToPlanPickResponse(const PickPlanResult& result, const ModelingResult& modeling,
                                        const std::string& profile, std::uint64_t seed) {
  v1::PlanPickResponse response;
  for (const PickPlan& plan : result.plans) {
    v1::PickPlan* p = response.add_plans();
    p->set_tube_id(plan.tube_id);
    ToProto(plan.grasp.X_BinTcp, p->mutable_grasp()->mutable_tcp_pose());
    ToProto(plan.grasp.approach_Bin, p->mutable_grasp()->mutable_approach());
    p->mutable_grasp()->set_opening_width(plan.grasp.opening_width);
    for (const Eigen::Vector3d& w : plan.waypoints) ToProto(w, p->add_waypoints());
    p->set_trajectory_kind(ToProto(plan.kind));
    p->mutable_cost()->set_height(plan.costs.height);
    p->mutable_cost()->set_centre(plan.costs.centre);
    p->mutable_cost()->set_trajectory(plan.costs.trajectory);
    p->mutable_cost()->set_total(plan.costs.total);
    p->set_simulated_displacement(plan.displacement.value_or(0.0));
    if (plan.X_BinTcp_place) ToProto(*plan.X_BinTcp_place, p->mutable_place_tcp_pose());
  }
  for (const Tube& t : result.tubes) ToProto(t, response.add_tubes());
  response.set_bin_empty(result.bin_empty);
  response.set_used_simulation(result.used_simulation);
  *response.mutable_modeling() = ToModelTubesResponse(modeling, profile, seed);
  response.mutable_modeling()->clear_tubes();  // the classified tubes above supersede them
  for (const StageTiming& t : result.timings) {
    v1::StageTiming* pt = response.add_stage_timings();
    pt->set_stage(t.stage);
    pt->set_seconds(t.seconds);
  }
  response.set_total_seconds(result.total_seconds);
  const PlanningCounts& c = result.counts;
  v1::PlanningCounts* pc = response.mutable_counts();
  pc->set_tubes(c.tubes);
  pc->set_too_short(c.too_short);
  pc->set_non_occluded(c.non_occluded);
  pc->set_weakly_occluded(c.weakly_occluded);
  pc->set_strongly_occluded(c.strongly_occluded);
  pc->set_trajectories(c.trajectories);
  pc->set_simulated_trajectories(c.simulated_trajectories);
  pc->set_grasp_candidates(c.grasp_candidates);
  pc->set_rejected_section(c.rejected_section);
  pc->set_rejected_workspace(c.rejected_workspace);
  pc->set_rejected_tool(c.rejected_tool);
  pc->set_rejected_fingers(c.rejected_fingers);
  return response;
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
  }
  return v1::RESOLUTION_VARIANT_UNSPECIFIED;
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
    default:
      return std::nullopt;
  }
}

void ToProto(const ResolutionMotion& motion, v1::ResolutionMotion* out) {
  ToProto(motion.axis_Tcp, out->mutable_axis_tcp());
  out->set_angle(motion.angle);
  out->set_yaw(motion.yaw);
  for (const ResolutionWaypoint& w : motion.waypoints) {
    v1::ResolutionWaypoint* pw = out->add_waypoints();
    ToProto(w.X_BinTcpRotated, pw->mutable_tcp_pose());
    pw->set_description(w.description);
  }
  out->set_description(motion.description);
}

v1::AnalyzeWrenchResponse ToAnalyzeWrenchResponse(const HeldCount& count,
                                                  const std::optional<ResolutionPlan>& resolution,
                                                  const Eigen::Vector3d& delta_torque_Tcp) {
  v1::AnalyzeWrenchResponse response;
  response.set_outcome(ToProto(count.outcome));
  response.set_estimated_count(count.estimated_count);
  response.set_tube_weight(count.tube_weight);
  response.set_expected_force(count.expected_force);
  response.set_held_weight(count.held_weight);
  response.set_tube_ratio(count.tube_ratio);
  if (count.outcome == HeldOutcome::kMultiple) {
    ToProto(delta_torque_Tcp, response.mutable_delta_torque_tcp());
    if (resolution) {
      for (const ResolutionMotion& m : resolution->motions) ToProto(m, response.add_resolution_motions());
    }
  }
  return response;
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
