#include "wire/response_convert.h"

#include "wire/proto_convert.h"

namespace tubepick {
namespace {

void AddTimings(const std::vector<StageTiming>& timings,
                google::protobuf::RepeatedPtrField<v1::StageTiming>* out) {
  for (const StageTiming& t : timings) {
    v1::StageTiming* pt = out->Add();
    pt->set_stage(t.stage);
    pt->set_seconds(t.seconds);
  }
}

v1::PlanCertainty CertaintyToProto(PlanCertainty certainty) {
  switch (certainty) {
    case PlanCertainty::kSure:
      return v1::PLAN_CERTAINTY_SURE;
    case PlanCertainty::kSimulated:
      return v1::PLAN_CERTAINTY_SIMULATED;
    case PlanCertainty::kUnsure:
      return v1::PLAN_CERTAINTY_UNSURE;
  }
  return v1::PLAN_CERTAINTY_UNSPECIFIED;
}

v1::PickPlan PickPlanToProto(const PickPlan& plan) {
  v1::PickPlan p;
  p.set_tube_id(plan.tube_id);
  *p.mutable_grasp()->mutable_tcp_pose() = ToProto(plan.grasp.X_BinTcp);
  *p.mutable_grasp()->mutable_approach() = ToProto(plan.grasp.approach_Bin);
  p.mutable_grasp()->set_tilt(plan.grasp.tilt);
  p.mutable_grasp()->set_opening_width(plan.grasp.opening_width);
  for (const Eigen::Vector3d& w : plan.waypoints) *p.add_waypoints() = ToProto(w);
  p.set_trajectory_kind(ToProto(plan.kind));
  p.mutable_cost()->set_height(plan.costs.height);
  p.mutable_cost()->set_centre(plan.costs.centre);
  p.mutable_cost()->set_trajectory(plan.costs.trajectory);
  p.mutable_cost()->set_total(plan.costs.total);
  p.set_simulated_displacement(plan.displacement.value_or(0.0));
  if (plan.X_BinTcp_place) *p.mutable_place_tcp_pose() = ToProto(*plan.X_BinTcp_place);
  p.set_certainty(CertaintyToProto(plan.certainty));
  return p;
}

v1::PlanningCounts CountsToProto(const PlanningCounts& c) {
  v1::PlanningCounts pc;
  pc.set_tubes(c.tubes);
  pc.set_too_short(c.too_short);
  pc.set_non_occluded(c.non_occluded);
  pc.set_weakly_occluded(c.weakly_occluded);
  pc.set_strongly_occluded(c.strongly_occluded);
  pc.set_trajectories(c.trajectories);
  pc.set_simulated_trajectories(c.simulated_trajectories);
  pc.set_grasp_candidates(c.grasp_candidates);
  pc.set_rejected_section(c.rejected_section);
  pc.set_rejected_workspace(c.rejected_workspace);
  pc.set_rejected_tool(c.rejected_tool);
  pc.set_rejected_fingers(c.rejected_fingers);
  pc.set_rejected_approach(c.rejected_approach);
  pc.set_tilted_grasps(c.tilted_grasps);
  pc.set_non_occluded_lain_on(c.non_occluded_lain_on);
  pc.set_short_tubes_planned(c.short_tubes_planned);
  return pc;
}

}  // namespace

v1::ModelTubesResponse ToModelTubesResponse(const ModelingResult& result, const std::string& profile,
                                            std::uint64_t seed) {
  v1::ModelTubesResponse response;
  for (const Tube& t : result.tubes) *response.add_tubes() = ToProto(t);
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
  AddTimings(result.timings, response.mutable_stage_timings());
  response.set_total_seconds(result.total_seconds);
  response.set_profile(profile);
  response.set_seed(seed);
  for (const ModelingWarning& w : result.warnings) {
    v1::ModelingWarning* pw = response.add_warnings();
    pw->set_code(w.code);
    pw->set_message(w.message);
    pw->set_stated(w.stated);
    pw->set_observed(w.observed);
  }
  return response;
}

v1::PlanPickResponse ToPlanPickResponse(const PickPlanResult& result, const ModelingResult& modeling,
                                        const std::string& profile, std::uint64_t seed) {
  v1::PlanPickResponse response;
  for (const PickPlan& plan : result.plans) *response.add_plans() = PickPlanToProto(plan);
  for (const Tube& t : result.tubes) *response.add_tubes() = ToProto(t);
  response.set_bin_empty(result.bin_empty);
  response.set_used_simulation(result.used_simulation);
  *response.mutable_modeling() = ToModelTubesResponse(modeling, profile, seed);
  response.mutable_modeling()->clear_tubes();  // the classified tubes above supersede them
  AddTimings(result.timings, response.mutable_stage_timings());
  response.set_total_seconds(result.total_seconds);
  *response.mutable_counts() = CountsToProto(result.counts);
  return response;
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
  response.set_force_tolerance(count.force_tolerance);
  if (count.outcome == HeldOutcome::kMultiple) {
    *response.mutable_delta_torque_tcp() = ToProto(delta_torque_Tcp);
    if (resolution) {
      for (const ResolutionMotion& m : resolution->motions) *response.add_resolution_motions() = ToProto(m);
    }
  }
  return response;
}

}  // namespace tubepick
