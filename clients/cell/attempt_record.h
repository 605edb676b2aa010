#pragma once

// The parts of the controller's records (fields listed in clients/cell/cell_controller.h and
// docs/): built here so that the state machine only says which part it records when.

#include <cstdint>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_fault.h"
#include "clients/cell/nudge.h"
#include "devices/force_torque_sensor.h"
#include "tubepick/v1/planning.pb.h"

namespace tubepick::cell {

/// What an attempt record's common fields come from.
struct AttemptRecordHead {
  std::uint32_t round = 0;
  /// The attempt's number in the run (null for a scan without an attempt: set by the caller).
  std::uint32_t attempt = 0;
  std::uint32_t scan = 0;
  std::uint32_t plan_rank = 0;
  std::uint64_t seed = 0;
  nlohmann::json truth_before;
};

/// {"type": "attempt", round, attempt, scan, plan_rank, seed, tubes_left_plan, plans, bin_empty,
/// used_simulation, truth_before}.
nlohmann::json AttemptRecord(const AttemptRecordHead& head, const v1::PlanPickResponse& response);

/// {durations: {planning_wall_s, planning_server_s}}'s value.
nlohmann::json PlanningDurationsJson(double planning_wall_s, double planning_server_s);

/// Adds the plan's tube, trajectory_kind, cost and simulated_displacement to `record`.
void RecordPlan(nlohmann::json& record, const v1::PickPlan& plan);

/// {"rank", "tube", "check", "reason"}: one entry of skipped_plans (check: "failed_grasp",
/// "cell_frame", "robot_limits", "tool_clearance").
nlohmann::json SkippedPlanJson(int rank, std::uint32_t tube, const std::string& check,
                               const std::string& reason);

/// {"tcp_pose", "approach", "opening_width", "tilt"} (tilt: the plan's turn away from the
/// vertical approach, radians).
nlohmann::json GraspJson(const Eigen::Isometry3d& X_BinTcpGrasp, const Eigen::Vector3d& approach_Bin,
                         double opening_width, double tilt);

/// {"outcome", "estimated_count", "tube_ratio", "held_weight", "tube_weight", "force_tolerance",
/// "motions"}.
nlohmann::json AnalysisJson(const v1::AnalyzeWrenchResponse& analysis);

/// An attempt (or a scan without a plan) in a few words from its record: the lift's outcome and tubes
/// of tube.mass ("multiple 2.02 tubes"), the attempt's result when nothing was lifted ("grasp_failed"),
/// or "no plan" ("no plan (3 of 5 skipped)", "no plan, nudged tube 3").
std::string DescribeAttemptBriefly(const nlohmann::json& record);

/// {"available", "used": 0, "succeeded": false}.
nlohmann::json ResolutionJson(int available);

/// One entry of wrench.after_resolution: {"motion", "description", "wrench", "outcome", "tube_ratio"}.
nlohmann::json AfterResolutionJson(int m, const v1::ResolutionMotion& motion,
                                   const devices::WrenchReading& wrench,
                                   const v1::AnalyzeWrenchResponse& analysis);

/// {"tube", "contact", "wall_distance", "direction", "shift", "distance", "tcp_pose"}.
nlohmann::json NudgeJson(const NudgePlan& nudge);

/// {"device", "kind", "state", "error"}.
nlohmann::json FaultJson(const CellFault& fault);

/// {"type": "safe_stop", round, reason ("fault", "stopped"), device, kind, state, error, held
/// ("nothing", "tube", "unknown"), action ("stopped", "released_in_bin", "kept_closed", "load_on_tool"),
/// p_Bin_tcp (where the TCP ended, or null), message}. After a fault: the fault's device, kind, state and
/// error; after an operator stop (result.operator_stop): device "operator", kind "stop", the state
/// the stop came in and the operator's reason as error.
nlohmann::json SafeStopRecord(std::uint32_t round, const CellRunResult& result, const std::string& state);

/// {"state", "reason"}: the "stop" part of an attempt record the operator's stop ended.
nlohmann::json OperatorStopJson(const std::string& state, const std::string& why);

/// One PlannedMotion as JSON: {"kind", "state", "step", "tcp_pose", "via", "waypoints", "speed",
/// "gripper_opening", "gripper_force"} (absent parts null or empty).
nlohmann::json PlannedMotionJson(const PlannedMotion& motion);

/// {"type": "end", round, reason, message, picks, attempts, scans, nudges, lost, truth_start, truth}.
nlohmann::json EndRecord(std::uint32_t round, const CellRunResult& result, const nlohmann::json& truth_start,
                         const nlohmann::json& truth);

}  // namespace tubepick::cell
