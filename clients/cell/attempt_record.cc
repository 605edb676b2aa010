#include "clients/cell/attempt_record.h"

#include <fmt/core.h>

#include "clients/cell/cell_records.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {

nlohmann::json AttemptRecord(const AttemptRecordHead& head, const v1::PlanPickResponse& response) {
  nlohmann::json record{{"type", "attempt"},
                        {"round", head.round},
                        {"attempt", head.attempt},
                        {"scan", head.scan},
                        {"plan_rank", head.plan_rank},
                        {"seed", head.seed},
                        {"tubes_left_plan", response.tubes_size()},
                        {"plans", response.plans_size()},
                        {"bin_empty", response.bin_empty()},
                        {"used_simulation", response.used_simulation()},
                        {"truth_before", head.truth_before}};
  // Every tube of the scan was too short for a whole one; they were planned as a last resort.
  if (response.counts().short_tubes_planned()) record["short_tubes_planned"] = response.counts().too_short();
  // The modeling's warnings about the cell's inputs (e.g. a tube.length shorter than the scan shows).
  if (response.modeling().warnings_size() > 0) {
    nlohmann::json& warnings = record["planner_warnings"] = nlohmann::json::array();
    for (const v1::ModelingWarning& w : response.modeling().warnings()) {
      warnings.push_back({{"code", w.code()}, {"stated", w.stated()}, {"observed", w.observed()}});
    }
  }
  return record;
}

nlohmann::json PlanningDurationsJson(double planning_wall_s, double planning_server_s) {
  return {{"planning_wall_s", planning_wall_s}, {"planning_server_s", planning_server_s}};
}

void RecordPlan(nlohmann::json& record, const v1::PickPlan& plan) {
  record["tube"] = plan.tube_id();
  record["trajectory_kind"] = TrajectoryKindName(plan.trajectory_kind());
  record["cost"] = {{"height", plan.cost().height()},
                    {"centre", plan.cost().centre()},
                    {"trajectory", plan.cost().trajectory()},
                    {"total", plan.cost().total()}};
  record["simulated_displacement"] = plan.simulated_displacement();
  record["certainty"] = CertaintyName(plan.certainty());
}

nlohmann::json SkippedPlanJson(int rank, std::uint32_t tube, const std::string& check,
                               const std::string& reason) {
  return {{"rank", rank}, {"tube", tube}, {"check", check}, {"reason", reason}};
}

nlohmann::json GraspJson(const Eigen::Isometry3d& X_BinTcpGrasp, const Eigen::Vector3d& approach_Bin,
                         double opening_width, double tilt) {
  return {{"tcp_pose", PoseJson(X_BinTcpGrasp)},
          {"approach", VectorJson(approach_Bin)},
          {"opening_width", opening_width},
          {"tilt", tilt}};
}

nlohmann::json AnalysisJson(const v1::AnalyzeWrenchResponse& analysis) {
  return {{"outcome", HeldOutcomeName(analysis.outcome())},
          {"estimated_count", analysis.estimated_count()},
          {"tube_ratio", analysis.tube_ratio()},
          {"held_weight", analysis.held_weight()},
          {"tube_weight", analysis.tube_weight()},
          {"force_tolerance", analysis.force_tolerance()},
          {"motions", analysis.resolution_motions_size()}};
}

std::string DescribeAttemptBriefly(const nlohmann::json& record) {
  if (const auto a = record.find("analysis"); a != record.end() && a->is_object()) {
    return fmt::format("{} {:.2f} tubes", a->value("outcome", ""), a->value("tube_ratio", 0.0));
  }
  const std::string result = record.value("result", "unfinished");
  if (result == "nudge") return fmt::format("no plan, nudged tube {}", record["nudge"].value("tube", 0u));
  if (result != "no_plan") return result;
  if (const auto refused = record.find("nudge_not_repeated"); refused != record.end())
    return fmt::format("no plan, tube {} not nudged again (the last nudge there moved nothing)",
                       refused->at("nudge").value("tube", 0u));
  const std::size_t skipped = record.value("skipped_plans", nlohmann::json::array()).size();
  return skipped == 0 ? std::string("no plan")
                      : fmt::format("no plan ({} of {} skipped)", skipped, record.value("plans", 0));
}

nlohmann::json ResolutionJson(int available) {
  return {{"available", available}, {"used", 0}, {"succeeded", false}};
}

nlohmann::json AfterResolutionJson(int m, const v1::ResolutionMotion& motion,
                                   const devices::WrenchReading& wrench,
                                   const v1::AnalyzeWrenchResponse& analysis) {
  return {{"motion", m},
          {"description", motion.description()},
          {"wrench", WrenchJson(wrench)},
          {"outcome", HeldOutcomeName(analysis.outcome())},
          {"tube_ratio", analysis.tube_ratio()}};
}

nlohmann::json NudgeJson(const NudgePlan& nudge) {
  return {{"tube", nudge.tube_id},
          {"contact", VectorJson(nudge.p_Bin_contact)},
          {"wall_distance", nudge.wall_distance},
          {"direction", VectorJson(nudge.direction)},
          {"shift", nudge.shift},
          {"distance", nudge.distance},
          {"tcp_pose", PoseJson(nudge.X_BinTcpPress)}};
}

nlohmann::json FaultJson(const CellFault& fault) {
  return {{"device", fault.device()},
          {"kind", ToString(fault.kind())},
          {"state", fault.state()},
          {"error", fault.error()}};
}

nlohmann::json SafeStopRecord(std::uint32_t round, const CellRunResult& result, const std::string& state) {
  nlohmann::json p_Bin_tcp = nullptr;
  if (result.safe_stop && result.safe_stop->p_Bin_tcp) {
    const Eigen::Vector3d& p = *result.safe_stop->p_Bin_tcp;
    p_Bin_tcp = {p.x(), p.y(), p.z()};
  }
  nlohmann::json record = {{"type", "safe_stop"}, {"round", round}, {"reason", ToString(result.reason)}};
  if (result.fault) {
    record["device"] = result.fault->device();
    record["kind"] = ToString(result.fault->kind());
    record["state"] = result.fault->state();
    record["error"] = result.fault->error();
  } else {
    record["device"] = "operator";
    record["kind"] = "stop";
    record["state"] = state;
    record["error"] = result.operator_stop.value_or("operator stop");
  }
  record["held"] = ToString(result.safe_stop ? result.safe_stop->held : Held::kNothing);
  record["action"] = result.safe_stop ? result.safe_stop->action : "stopped";
  record["p_Bin_tcp"] = p_Bin_tcp;
  record["message"] = result.message;
  return record;
}

nlohmann::json OperatorStopJson(const std::string& state, const std::string& why) {
  return {{"state", state}, {"reason", why}};
}

nlohmann::json PlannedMotionJson(const PlannedMotion& motion) {
  nlohmann::json via = nlohmann::json::array();
  for (const Eigen::Isometry3d& X : motion.via) via.push_back(PoseJson(X));
  nlohmann::json waypoints = nlohmann::json::array();
  for (const Eigen::Vector3d& w : motion.waypoints_Bin) waypoints.push_back(VectorJson(w));
  return {{"kind", ToString(motion.kind)},
          {"state", ToString(motion.state)},
          {"step", motion.step},
          {"tcp_pose", PoseJson(motion.X_BinTcp)},
          {"via", via},
          {"waypoints", waypoints},
          {"speed", motion.speed},
          {"gripper_opening",
           motion.gripper_opening ? nlohmann::json(*motion.gripper_opening) : nlohmann::json()},
          {"gripper_force", motion.gripper_force ? nlohmann::json(*motion.gripper_force) : nlohmann::json()}};
}

nlohmann::json EndRecord(std::uint32_t round, const CellRunResult& result, const nlohmann::json& truth_start,
                         const nlohmann::json& truth) {
  return {{"type", "end"},
          {"round", round},
          {"reason", ToString(result.reason)},
          {"message", result.message},
          {"picks", result.picks},
          {"attempts", result.attempts},
          {"scans", result.scans},
          {"nudges", result.nudges},
          {"lost", result.lost},
          {"tubes_expected", result.tubes_expected},
          {"tubes_unaccounted", result.tubes_unaccounted},
          {"truth_start", truth_start},
          {"truth", truth}};
}

}  // namespace tubepick::cell
