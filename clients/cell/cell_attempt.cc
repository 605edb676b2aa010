// One picking attempt of the cell controller, step by step: approach → reference → grasp → lift →
// analyze → place | release | resolve → place | release | put back; and the nudge's motions.
// Poses are X_BinTcp…: the TCP in the bin frame.

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "clients/cell/attempt_record.h"
#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_controller_internal.h"
#include "clients/cell/cell_frame_check.h"
#include "clients/cell/local_wrench_analysis.h"
#include "clients/cell/tool_clearance.h"
#include "core/wrench/resolution_hold.h"
#include "core/wrench/tube_mass_check.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {
using detail::CallDevice;
using detail::PlannerPose;
using detail::WithHeight;

namespace {

/// The plan's unit approach direction (bin axes); the TCP's z axis when the plan gives none.
Eigen::Vector3d ApproachOf(const v1::PickPlan& plan, const Eigen::Isometry3d& X_BinTcpGrasp) {
  Eigen::Vector3d approach_Bin = FromProto(plan.grasp().approach());
  if (!approach_Bin.allFinite() || approach_Bin.norm() < 1e-9) approach_Bin = X_BinTcpGrasp.linear().col(2);
  return approach_Bin.normalized();
}

/// The grasp pose backed off `height` against the approach direction.
Eigen::Isometry3d PreGraspPose(const Eigen::Isometry3d& X_BinTcpGrasp, const Eigen::Vector3d& approach_Bin,
                               double height) {
  Eigen::Isometry3d X_BinTcpPreGrasp = X_BinTcpGrasp;
  X_BinTcpPreGrasp.translation() -= height * approach_Bin;
  return X_BinTcpPreGrasp;
}

/// The plan's lift waypoints: TCP translations from the grasp pose, bin axes.
std::vector<Eigen::Vector3d> WaypointsOf(const v1::PickPlan& plan) {
  std::vector<Eigen::Vector3d> waypoints_Bin;
  for (const v1::Vector3& w : plan.waypoints()) waypoints_Bin.push_back(FromProto(w));
  return waypoints_Bin;
}

/// Why motion m of a resolution, turned about the TCP at the hold pose (`shift` from the lift
/// pose), leaves the arm's reach or wrist limits (a tool tilted at the grasp turned further), or
/// nullopt.
std::optional<std::string> ResolutionReachProblem(const devices::RobotLimits& limits,
                                                  const v1::ResolutionMotion& motion, int m,
                                                  const Eigen::Translation3d& shift, CellState state) {
  for (int w = 0; w < motion.waypoints_size(); ++w) {
    const Eigen::Isometry3d X_BinTcp =
        shift * PlannerPose(motion.waypoints(w).tcp_pose(),
                            fmt::format("resolution_motions[{}].waypoints[{}].tcp_pose", m, w), state);
    if (std::string problem = limits.Problem(X_BinTcp); !problem.empty())
      return fmt::format("waypoint {}: {}", w, problem);
  }
  return std::nullopt;
}

}  // namespace

// ---------------------------------------------------------------- plan

std::optional<CellController::PlanSkip> CellController::ExecutionProblem(const v1::PlanPickResponse& response,
                                                                         int rank) const {
  const v1::PickPlan& plan = response.plans(rank);
  const Eigen::Isometry3d X_BinTcpGrasp =
      PlannerPose(plan.grasp().tcp_pose(), fmt::format("plans[{}].grasp.tcp_pose", rank), state_);
  const std::vector<Eigen::Vector3d> waypoints_Bin = WaypointsOf(plan);
  const Eigen::Isometry3d X_BinTcpPreGrasp =
      PreGraspPose(X_BinTcpGrasp, ApproachOf(plan, X_BinTcpGrasp), params_.approach_height);
  std::optional<Eigen::Isometry3d> X_BinTcpPlace;
  if (plan.has_place_tcp_pose())
    X_BinTcpPlace = PlannerPose(plan.place_tcp_pose(), fmt::format("plans[{}].place_tcp_pose", rank), state_);

  // This controller's cell first: a plan from a planner with another cell fails everything else
  // too, with reasons that do not say why.
  PlanFrameInput frame_input{X_BinTcpGrasp, X_BinTcpPreGrasp, waypoints_Bin, X_BinTcpPlace, nullptr};
  for (const v1::Tube& tube : response.tubes())
    if (tube.id() == plan.tube_id()) frame_input.tube = &tube;
  if (std::optional<std::string> problem = CellFrameProblem(cell_, params_.cell_check, frame_input))
    return PlanSkip{"cell_frame", std::move(*problem)};

  // The arm's reach and wrist limits: pre-grasp, grasp, every lift waypoint and the placement.
  const devices::RobotLimits limits = devices_.robot->Limits();
  std::vector<std::pair<std::string, Eigen::Isometry3d>> X_BinTcp_checked;
  X_BinTcp_checked.emplace_back("pre-grasp", X_BinTcpPreGrasp);
  X_BinTcp_checked.emplace_back("grasp", X_BinTcpGrasp);
  for (std::size_t i = 0; i < waypoints_Bin.size(); ++i) {
    Eigen::Isometry3d X_BinTcpWaypoint = X_BinTcpGrasp;
    X_BinTcpWaypoint.translation() += waypoints_Bin[i];
    X_BinTcp_checked.emplace_back(fmt::format("waypoint {}", i), X_BinTcpWaypoint);
  }
  if (X_BinTcpPlace) X_BinTcp_checked.emplace_back("place", *X_BinTcpPlace);
  for (const auto& [what, X_BinTcp] : X_BinTcp_checked) {
    const std::string problem = limits.Problem(X_BinTcp);
    if (!problem.empty())
      return PlanSkip{"robot_limits", fmt::format("robot limits at the {}: {}", what, problem)};
  }
  if (!params_.check_tool_clearance) return std::nullopt;
  if (std::optional<std::string> problem = ToolClearanceProblem(cell_, params_.tool, X_BinTcpGrasp,
                                                                plan.grasp().opening_width(), waypoints_Bin))
    return PlanSkip{"tool_clearance", std::move(*problem)};
  return std::nullopt;
}

CellController::PlanPoses CellController::PosesOf(const v1::PickPlan& plan, int rank) const {
  const std::string field = fmt::format("plans[{}]", rank);
  PlanPoses poses;
  poses.X_BinTcpGrasp = PlannerPose(plan.grasp().tcp_pose(), field + ".grasp.tcp_pose", CellState::kPlan);
  poses.X_BinTcpPlace = PlannerPose(plan.place_tcp_pose(), field + ".place_tcp_pose", CellState::kPlan);
  if (plan.waypoints_size() == 0)
    throw CellFault("planner", FaultKind::kServerError, ToString(CellState::kPlan),
                    field + ".waypoints: empty (a trajectory starts with (0, 0, 0))");
  poses.approach_Bin = ApproachOf(plan, poses.X_BinTcpGrasp);
  poses.X_BinTcpPreGrasp = PreGraspPose(poses.X_BinTcpGrasp, poses.approach_Bin, params_.approach_height);
  poses.waypoints_Bin = WaypointsOf(plan);
  return poses;
}

// ---------------------------------------------------------------- attempt

void CellController::ExecutePlan(const v1::PickPlan& plan, int rank, Attempt& attempt) {
  RecordPlan(attempt.record, plan);
  const PlanPoses poses = PosesOf(plan, rank);
  const double opening_width = plan.grasp().opening_width();
  attempt.record["grasp"] =
      GraspJson(poses.X_BinTcpGrasp, poses.approach_Bin, opening_width, plan.grasp().tilt());
  attempt.p_Bin_grasp = poses.X_BinTcpGrasp.translation();

  Approach(poses.X_BinTcpPreGrasp, opening_width, attempt);
  const devices::WrenchReading reference = TakeReference(attempt);
  if (!Grasp(poses.X_BinTcpGrasp, attempt)) {
    ReleaseFailedGrasp(poses.X_BinTcpGrasp, poses.X_BinTcpPreGrasp, reference, attempt);
    attempt.result = AttemptResult::kGraspFailed;
    return;
  }
  try {
    const Eigen::Isometry3d X_BinTcpLift = Lift(poses.waypoints_Bin, attempt);
    CheckStillHolding("lift", attempt);
    devices::WrenchReading lifted;
    const v1::AnalyzeWrenchResponse analysis = AnalyzeLift(reference, X_BinTcpLift, attempt, &lifted);
    attempt.result = Conclude(analysis.outcome(), poses.X_BinTcpPlace, reference, attempt);
    if (!attempt.result) attempt.result = Resolve(analysis, reference, lifted, poses, X_BinTcpLift, attempt);
  } catch (const TubeLost& lost) {
    RecordLost(lost, attempt);
    attempt.result = AttemptResult::kLost;
  }
}

/// Transit to the pre-grasp pose, open to the grasp width.
void CellController::Approach(const Eigen::Isometry3d& X_BinTcpPreGrasp, double opening_width,
                              Attempt& attempt) {
  Enter(CellState::kApproach);
  TransitTo(X_BinTcpPreGrasp, &attempt);
  if (opening_width > 0.0) {
    CheckGripper(CallDevice("gripper", state_, [&] {
      return devices_.gripper->MoveTo(opening_width, params_.gripper_speed, params_.gripper_force,
                                      params_.gripper_timeout);
    }));
  }
}

/// The F/T reference: the gripper is empty and already in the orientation of the lift.
devices::WrenchReading CellController::TakeReference(Attempt& attempt) {
  Enter(CellState::kReference);
  const devices::WrenchReading reference = ReadWrench();
  attempt.record["wrench"] = {{"reference", WrenchJson(reference)}};
  return reference;
}

bool CellController::Grasp(const Eigen::Isometry3d& X_BinTcpGrasp, Attempt& attempt) {
  Enter(CellState::kGrasp);
  MoveTo(X_BinTcpGrasp, params_.approach_speed, &attempt);
  held_ = Held::kUnknown;  // closing: until the gripper reports
  const devices::GripperStatus closed = CloseGripper();
  attempt.record["gripper"] = GripperJson(closed);
  const bool object = closed.object == devices::GripperObject::kStoppedClosing;
  held_ = object ? Held::kTube : Held::kNothing;
  return object;
}

/// Nothing grasped: open, back up to the pre-grasp pose, nothing caught on the tool, home.
void CellController::ReleaseFailedGrasp(const Eigen::Isometry3d& X_BinTcpGrasp,
                                        const Eigen::Isometry3d& X_BinTcpPreGrasp,
                                        const devices::WrenchReading& reference, Attempt& attempt) {
  Enter(CellState::kRelease);
  OpenGripper();
  MoveTo(X_BinTcpPreGrasp, params_.approach_speed, &attempt);
  CheckToolEmpty(reference, "after_failed_grasp", X_BinTcpGrasp, attempt);
  GoHome(&attempt);
}

Eigen::Isometry3d CellController::Lift(const std::vector<Eigen::Vector3d>& waypoints_Bin, Attempt& attempt) {
  Enter(CellState::kLift);
  MoveThrough(waypoints_Bin, params_.lift_speed, &attempt);
  return CurrentPose();
}

/// A reading at the lift pose and its analysis against the reference.
v1::AnalyzeWrenchResponse CellController::AnalyzeLift(const devices::WrenchReading& reference,
                                                      const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt,
                                                      devices::WrenchReading* lifted) {
  Enter(CellState::kAnalyze);
  nlohmann::json& record = attempt.record;
  *lifted = ReadWrench();
  record["wrench"]["lift"] = WrenchJson(*lifted);
  record["wrench"]["after_resolution"] = nlohmann::json::array();
  const v1::AnalyzeWrenchResponse analysis = Analyze(reference, *lifted, X_BinTcpLift, attempt);
  record["analysis"] = AnalysisJson(analysis);
  record["resolution"] = ResolutionJson(analysis.resolution_motions_size());
  CheckLiftWeights(analysis.tube_ratio(), attempt);
  return analysis;
}

/// Whether the cell's recent lifts still fit tube.mass (CheckTubeMass): the doubt goes into the attempt's
/// record and, the first time, the log. Algorithm 3's decision stands either way.
void CellController::CheckLiftWeights(double tube_ratio, Attempt& attempt) {
  if (!params_.tube_mass_check.enabled) return;
  // CheckTubeMass reads the last `window` lifts only.
  lift_ratios_.push_back(tube_ratio);
  if (lift_ratios_.size() > params_.tube_mass_check.limits.window) lift_ratios_.erase(lift_ratios_.begin());
  const std::optional<TubeMassDoubt> doubt =
      CheckTubeMass(lift_ratios_, cell_.tube.mass, params_.tube_mass_check.limits);
  if (!doubt) return;
  attempt.record["tube_mass_doubt"] = {{"message", doubt->message},
                                       {"lifts", doubt->lifts},
                                       {"min_ratio", doubt->min_ratio},
                                       {"max_ratio", doubt->max_ratio},
                                       {"median_ratio", doubt->median_ratio},
                                       {"tube_mass", doubt->tube_mass},
                                       {"mass_if_single", doubt->mass_if_single}};
  spdlog::log(tube_mass_doubt_said_ ? spdlog::level::debug : spdlog::level::warn, "cell: round {}: {}{}",
              round_, doubt->message,
              tube_mass_doubt_said_ ? "" : " (said once; the attempt records carry it as tube_mass_doubt)");
  tube_mass_doubt_said_ = true;
}

std::optional<CellController::AttemptResult> CellController::Conclude(v1::HeldOutcome outcome,
                                                                      const Eigen::Isometry3d& X_BinTcpPlace,
                                                                      const devices::WrenchReading& reference,
                                                                      Attempt& attempt) {
  switch (outcome) {
    case v1::HELD_OUTCOME_SINGLE:
      Place(X_BinTcpPlace, reference, attempt);
      return AttemptResult::kPicked;
    case v1::HELD_OUTCOME_NONE:
      ReleaseEmpty(attempt);
      return AttemptResult::kNone;
    default:
      return std::nullopt;
  }
}

/// Several tubes: carried over the bin's middle (resolution_hold_over_bin), then the resolution
/// motions in order there (with resolution_replan, each after the first planned from the reading
/// before it, and up to resolution_extra_motions more), each paused at its tilt (resolution_dwell)
/// and followed by a new reading at the hold pose; unresolved, back to the lift pose and put back.
CellController::AttemptResult CellController::Resolve(const v1::AnalyzeWrenchResponse& analysis,
                                                      const devices::WrenchReading& reference,
                                                      const devices::WrenchReading& lifted,
                                                      const PlanPoses& poses,
                                                      const Eigen::Isometry3d& X_BinTcpLift,
                                                      Attempt& attempt) {
  Enter(CellState::kResolve);
  nlohmann::json& resolution = attempt.record["resolution"];
  Eigen::Vector3d shift_Bin = Eigen::Vector3d::Zero();
  if (params_.resolution_hold_over_bin && analysis.resolution_motions_size() > 0) {
    const ResolutionHold hold =
        PlanResolutionHold(devices::AsWrench(reference), devices::AsWrench(lifted), X_BinTcpLift,
                           cell_.bin.inner_size, params_.resolution_wall_margin);
    shift_Bin = hold.shift_Bin;
    resolution["payload_offset"] = {hold.p_TcpPayload_Bin.x(), hold.p_TcpPayload_Bin.y()};
  }
  resolution["hold_shift"] = {shift_Bin.x(), shift_Bin.y()};
  const Eigen::Translation3d shift(shift_Bin);
  const Eigen::Isometry3d X_BinTcpHold = shift * X_BinTcpLift;
  if (!shift_Bin.isZero()) MoveTo(X_BinTcpHold, params_.lift_speed, &attempt);
  // resolution_rest_load lets the tangle down no lower than a put-back would.
  Eigen::Isometry3d X_BinTcpLowest = X_BinTcpHold;
  X_BinTcpLowest.translation().z() = std::min(X_BinTcpHold.translation().z(),
                                              poses.X_BinTcpGrasp.translation().z() + params_.release_height);
  devices::WrenchReading held = lifted;
  const devices::RobotLimits limits = devices_.robot->Limits();
  // The analysis of the reading after the last motion driven, `again_after` (resolution_replan).
  std::optional<v1::AnalyzeWrenchResponse> again;
  int again_after = -1;
  const auto planned = static_cast<std::size_t>(analysis.resolution_motions_size());
  for (int m = 0;; ++m) {
    const ResolutionMotionSource source =
        NextResolutionMotion(params_, m, planned, again && again->resolution_motions_size() > 0);
    if (source == ResolutionMotionSource::kNone) break;
    // Replanned: the first motion of the reading at the hold pose, planned about the TCP there.
    const bool replanned = source == ResolutionMotionSource::kReading;
    // A copy: `again` is replaced by the reading after this motion.
    const v1::ResolutionMotion motion =
        replanned ? again->resolution_motions(0) : analysis.resolution_motions(m);
    const Eigen::Translation3d motion_shift = replanned ? Eigen::Translation3d::Identity() : shift;
    if (const std::optional<std::string> problem =
            ResolutionReachProblem(limits, motion, m, motion_shift, state_)) {
      spdlog::info("cell: round {}: resolution motion {} skipped, beyond the robot's limits at {}", round_, m,
                   *problem);
      resolution["beyond_limits"].push_back({{"motion", m}, {"problem", *problem}});
      // That reading plans nothing else: the plan's next motion, if any, is tried instead.
      if (replanned) again.reset();
      continue;
    }
    if (replanned) {
      spdlog::info("cell: round {}: resolution motion {} planned from the reading after motion {}: {}",
                   round_, m, again_after, motion.description());
      resolution["replanned"].push_back(m);
    }
    resolution["used"] = m + 1;
    again =
        ResolutionMotion(motion, m, reference, motion_shift, X_BinTcpHold, X_BinTcpLowest, attempt, &held);
    again_after = m;
    if (again->outcome() == v1::HELD_OUTCOME_SINGLE) resolution["succeeded"] = true;
    if (const std::optional<AttemptResult> result =
            Conclude(again->outcome(), poses.X_BinTcpPlace, reference, attempt))
      return *result;
  }
  const Eigen::Isometry3d X_BinTcpPutBack = PutBackPose(reference, held, X_BinTcpLift, attempt);
  if (!X_BinTcpPutBack.isApprox(X_BinTcpHold)) MoveTo(X_BinTcpPutBack, params_.lift_speed, &attempt);
  PutBack(poses.X_BinTcpGrasp, X_BinTcpPutBack, reference, attempt);
  return AttemptResult::kMultipleReturned;
}

Eigen::Isometry3d CellController::PutBackPose(const devices::WrenchReading& reference,
                                              const devices::WrenchReading& held,
                                              const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt) const {
  const Payload payload =
      PayloadOnTool(devices::AsWrench(reference), devices::AsWrench(held), X_BinTcpLift.linear());
  nlohmann::json& resolution = attempt.record["resolution"];
  resolution["put_back_payload_offset"] = {payload.p_TcpPayload_Bin.x(), payload.p_TcpPayload_Bin.y()};
  // A reading no free-hanging load gives says nothing of where the tangle would lie down: the
  // put-back is where the lift was.
  const bool believable = HangsFromTheTool(payload, cell_.tube.length);
  if (!believable) {
    spdlog::warn(
        "cell: round {}: the reading after the resolution puts the payload's centre of mass "
        "{:.2f} m from the TCP ({:.2f} N, {:.2f} N*m), farther than a tube's length ({:.2f} m): "
        "not a load hanging free (something pulls on it?); put back where it was lifted",
        round_, payload.p_TcpPayload_Bin.norm(), payload.weight, (held.torque - reference.torque).norm(),
        cell_.tube.length);
    resolution["put_back_payload_implausible"] = true;
  }
  const Eigen::Vector3d shift_Bin =
      believable ? PlanPutBackShift(X_BinTcpLift.translation(), payload.p_TcpPayload_Bin,
                                    cell_.bin.inner_size, params_.put_back_margin)
                 : Eigen::Vector3d::Zero();
  resolution["put_back_shift"] = {shift_Bin.x(), shift_Bin.y()};
  if (!shift_Bin.isZero()) {
    const Eigen::Vector3d p_Bin_payload = X_BinTcpLift.translation() + payload.p_TcpPayload_Bin;
    spdlog::info(
        "cell: round {}: the tubes not freed hang with their centre of mass at ({:.3f}, {:.3f}) m, less than "
        "{:.2f} m inside a wall: put back {:.3f} m further inside",
        round_, p_Bin_payload.x(), p_Bin_payload.y(), params_.put_back_margin, shift_Bin.norm());
  }
  return Eigen::Translation3d(shift_Bin) * X_BinTcpLift;
}

v1::AnalyzeWrenchResponse CellController::ResolutionMotion(const v1::ResolutionMotion& motion, int m,
                                                           const devices::WrenchReading& reference,
                                                           const Eigen::Translation3d& shift,
                                                           const Eigen::Isometry3d& X_BinTcpHold,
                                                           const Eigen::Isometry3d& X_BinTcpLowest,
                                                           Attempt& attempt, devices::WrenchReading* after) {
  Eigen::Translation3d down = Eigen::Translation3d::Identity();
  if (params_.resolution_rest_load > 0.0) {
    down = LowerToRest(X_BinTcpHold, X_BinTcpLowest, reference, attempt);
    if (const std::optional<std::string> problem =
            ResolutionReachProblem(devices_.robot->Limits(), motion, m, down * shift, state_)) {
      spdlog::info(
          "cell: round {}: resolution motion {} turns at the hold pose: {:.3f} m lower it is beyond the "
          "robot's limits at {}",
          round_, m, -down.z(), *problem);
      attempt.record["resolution"]["lowered_beyond_limits"].push_back({{"motion", m}, {"problem", *problem}});
      MoveTo(X_BinTcpHold, params_.lift_speed, &attempt);
      down = Eigen::Translation3d::Identity();
    }
  }
  // The planner's waypoints turn about the TCP at the lift pose; the same turns about the TCP at
  // the hold pose (or below it) are the waypoints moved by the hold's shift (and the way down).
  for (int w = 0; w < motion.waypoints_size(); ++w) {
    const Eigen::Isometry3d X_BinTcpWaypoint =
        down * shift *
        PlannerPose(motion.waypoints(w).tcp_pose(),
                    fmt::format("resolution_motions[{}].waypoints[{}].tcp_pose", m, w), state_);
    MoveTo(X_BinTcpWaypoint, params_.resolution_speed, &attempt);
  }
  if (params_.resolution_dwell > 0.0) HoldStill(params_.resolution_dwell, &attempt);
  if (down.translation().z() < -detail::kSameHeight)
    MoveTo(down * X_BinTcpHold, params_.resolution_speed, &attempt);
  MoveTo(X_BinTcpHold, params_.resolution_speed, &attempt);
  CheckStillHolding("resolve", attempt);
  *after = ReadWrench();
  const v1::AnalyzeWrenchResponse again = Analyze(reference, *after, X_BinTcpHold, attempt);
  attempt.record["wrench"]["after_resolution"].push_back(AfterResolutionJson(m, motion, *after, again));
  return again;
}

Eigen::Translation3d CellController::LowerToRest(const Eigen::Isometry3d& X_BinTcpHold,
                                                 const Eigen::Isometry3d& X_BinTcpLowest,
                                                 const devices::WrenchReading& reference, Attempt& attempt) {
  const double below = params_.resolution_rest_load * TubeWeight();
  const std::optional<Lighter> rest =
      DescendUntilLighter(X_BinTcpHold, X_BinTcpLowest, reference, below, "resolution_unsettled", attempt);
  const Eigen::Isometry3d X_BinTcpLow = rest ? rest->X_BinTcp : X_BinTcpLowest;
  const double lowered = X_BinTcpHold.translation().z() - X_BinTcpLow.translation().z();
  attempt.record["resolution"]["lowered"].push_back(lowered);
  spdlog::info(
      "cell: round {}: turning {:.3f} m below the hold pose, {}", round_, lowered,
      rest ? fmt::format("where {:.2f} N hang on the tool (under {:.1f} tube weights: the others rest)",
                         rest->load, params_.resolution_rest_load)
           : std::string("as low as a put-back goes (the load never got lighter)"));
  return Eigen::Translation3d(X_BinTcpLow.translation() - X_BinTcpHold.translation());
}

// ---------------------------------------------------------------- endings

/// One tube held: transit above the place pose (the gripper's object status checked after every
/// segment), a reading there that must still weigh a tube, down, the status once more, open, up,
/// a reading that must weigh nothing (a hose hooked on a pad is not carried home), home.
void CellController::Place(const Eigen::Isometry3d& X_BinTcpPlanned, const devices::WrenchReading& reference,
                           Attempt& attempt) {
  Enter(CellState::kPlace);
  const Eigen::Isometry3d X_BinTcpPlace = ClearOfThePlaceSurface(X_BinTcpPlanned, attempt);
  Eigen::Isometry3d X_BinTcpAbovePlace = X_BinTcpPlace;
  X_BinTcpAbovePlace.translation().z() += params_.place_approach_height;
  TransitTo(X_BinTcpAbovePlace, &attempt, [&] { CheckStillHolding("place_transit", attempt); });
  v1::AnalyzeWrenchResponse check;
  // Readings that keep disagreeing above the place: the held tube pressing on the place surface (a
  // part the model missed hangs lower than the model). Higher up it hangs free; a sensor at fault
  // disagrees there too. Without the recheck, they are the F/T fault they look like.
  const bool loaded =
      params_.place_recheck_height > 0.0
          ? LoadBeforePlaceUnlessPressing(reference, "before_place", attempt, &check).value_or(false)
          : LoadBeforePlace(reference, "before_place", attempt, &check);
  if (!loaded) {
    // Light (or pressing) while the fingers still hold something: resting on the place surface,
    // or lost.
    CheckStillHolding("place_transit", attempt);
    if (params_.place_recheck_height > 0.0) {
      X_BinTcpAbovePlace.translation().z() += params_.place_recheck_height;
      MoveTo(X_BinTcpAbovePlace, params_.approach_speed, &attempt);
    }
    if (params_.place_recheck_height == 0.0 ||
        !LoadBeforePlace(reference, "before_place_recheck", attempt, &check)) {
      throw TubeLost("place_transit", "wrench",
                     fmt::format("the load above the place pose weighs {:.2f} N more than the empty gripper "
                                 "(one tube: {:.2f} N){}",
                                 check.held_weight(), check.tube_weight(),
                                 params_.place_recheck_height > 0.0
                                     ? fmt::format(", also {:.2f} m higher", params_.place_recheck_height)
                                     : ""));
    }
  }
  DescendOntoPlace(X_BinTcpPlace, reference, attempt);
  CheckStillHolding("place_descent", attempt);
  OpenGripper();
  attempt.record["placed"] = true;  // a fault on the way home does not undo the pick
  MoveTo(X_BinTcpAbovePlace, params_.approach_speed, &attempt);
  CheckToolEmpty(reference, "after_place", X_BinTcpPlace, attempt);
  GoHome(&attempt);
}

Eigen::Isometry3d CellController::ClearOfThePlaceSurface(const Eigen::Isometry3d& X_BinTcpPlanned,
                                                         Attempt& attempt) const {
  const Eigen::Isometry3d X_BinTcpPlace =
      PlacePoseClearOfTheSurface(params_, cell_.tube.radius, X_BinTcpPlanned);
  const double raised = X_BinTcpPlace.translation().z() - X_BinTcpPlanned.translation().z();
  if (raised <= 0.0) return X_BinTcpPlace;
  attempt.record["place_raised"] = raised;
  spdlog::info(
      "cell: round {}: the planned place pose would bring the tool {:.3f} m from the place surface "
      "(place_surface_height {:.3f} m, tool.margin {:.3f} m): placing {:.3f} m higher",
      round_, params_.tool.margin - raised, params_.place_surface_height, params_.tool.margin, raised);
  return X_BinTcpPlace;
}

void CellController::DescendOntoPlace(const Eigen::Isometry3d& X_BinTcpPlace,
                                      const devices::WrenchReading& reference, Attempt& attempt) {
  for (const Eigen::Isometry3d& X_BinTcpStep : PlaceDescentSteps(params_, CurrentPose(), X_BinTcpPlace)) {
    MoveTo(X_BinTcpStep, params_.approach_speed, &attempt);
    // Readings that keep disagreeing one step lower than a steady one: a rigid tube jammed between
    // the pads and the surface. It is down: open.
    v1::AnalyzeWrenchResponse check;
    const bool resting =
        !LoadBeforePlaceUnlessPressing(reference, "place_descent", attempt, &check).value_or(false);
    if (resting) {
      const double above = X_BinTcpStep.translation().z() - X_BinTcpPlace.translation().z();
      attempt.record["place_touchdown"] = above;
      spdlog::info(
          "cell: round {}: the tube rests on the place surface {:.3f} m above the place pose: "
          "opening there",
          round_, above);
      return;
    }
  }
  MoveTo(X_BinTcpPlace, params_.approach_speed, &attempt);
}

void CellController::CheckStillHolding(const char* where, Attempt& attempt) {
  const devices::GripperStatus status = CheckGripper(
      CallDevice("gripper", state_, [&] { return devices_.gripper->Status(params_.gripper_timeout); }));
  if (status.object == devices::GripperObject::kStoppedClosing) return;
  held_ = Held::kNothing;
  attempt.record["gripper_lost"] = GripperJson(status);
  throw TubeLost(
      where, "gripper_status",
      fmt::format("the gripper no longer reports an object (fingers at {:.1f} mm)", status.opening * 1e3));
}

bool CellController::LoadBeforePlace(const devices::WrenchReading& reference, const char* key,
                                     Attempt& attempt, v1::AnalyzeWrenchResponse* check) {
  const devices::WrenchReading above = ReadWrench();
  *check = LocalAnalyzeWrench(WrenchRequest(reference, above, CurrentPose()), params_.profile);
  attempt.record["wrench"][key] = WrenchJson(above);
  return check->outcome() != v1::HELD_OUTCOME_NONE;
}

std::optional<bool> CellController::LoadBeforePlaceUnlessPressing(const devices::WrenchReading& reference,
                                                                  const char* key, Attempt& attempt,
                                                                  v1::AnalyzeWrenchResponse* check) {
  try {
    return LoadBeforePlace(reference, key, attempt, check);
  } catch (const CellFault& fault) {
    if (!detail::ReadingsDisagree(fault)) throw;
    attempt.record["wrench"][std::string(key) + "_unsettled"] = fault.error();
    spdlog::warn("cell: round {}: over the place pose ({}): {}", round_, key, fault.error());
    return std::nullopt;
  }
}

void CellController::RecordLost(const TubeLost& lost, Attempt& attempt) {
  nlohmann::json where = {{"state", lost.state},
                          {"detected_by", lost.detected_by},
                          {"detail", lost.what()},
                          {"device_time_s", DeviceNow()}};
  try {
    const Eigen::Vector3d p_Bin_tcp = CurrentPose().translation();
    where["p_Bin_tcp"] = {p_Bin_tcp.x(), p_Bin_tcp.y(), p_Bin_tcp.z()};
  } catch (const CellFault&) {
    where["p_Bin_tcp"] = nullptr;
  }
  attempt.record["lost"] = where;
  spdlog::warn("cell: round {}: tube lost during {} ({}: {})", round_, lost.state, lost.detected_by,
               lost.what());
  // The gripper says it holds nothing; should it be wrong, the fingers open at home (above the
  // place frame by default), not wherever the loss was noticed.
  GoHome(&attempt);
  Enter(CellState::kRelease);
  OpenGripper();
}

/// Nothing held after the lift: open where the gripper is, home.
void CellController::ReleaseEmpty(Attempt& attempt) {
  Enter(CellState::kRelease);
  OpenGripper();
  GoHome(&attempt);
}

void CellController::PutBack(const Eigen::Isometry3d& X_BinTcpGrasp, const Eigen::Isometry3d& X_BinTcpPutBack,
                             const devices::WrenchReading& reference, Attempt& attempt) {
  Enter(CellState::kReturnToBin);
  // Down towards just above the grasp height in F/T-read steps (LayDown), open where they rest, and
  // back up. Also at the lift pose: what hangs under the tube grasped came up from elsewhere and was
  // turned by the resolution, so the heap meets it before the grasp height (lowered there in one
  // move, a tangle of two trees was pushed on down through the heap and one went over a wall).
  Eigen::Isometry3d X_BinTcpRelease = X_BinTcpPutBack;
  X_BinTcpRelease.translation().z() =
      std::min(X_BinTcpPutBack.translation().z(), X_BinTcpGrasp.translation().z() + params_.release_height);
  const Eigen::Isometry3d X_BinTcpOpen = LayDown(X_BinTcpPutBack, X_BinTcpRelease, reference, attempt);
  OpenGripper();
  if (X_BinTcpOpen.translation().z() < X_BinTcpPutBack.translation().z() - detail::kSameHeight)
    MoveTo(X_BinTcpPutBack, params_.approach_speed, &attempt);
  CheckToolEmpty(reference, "after_put_back", X_BinTcpOpen, attempt);
  GoHome(&attempt);
}

std::optional<CellController::Lighter> CellController::DescendUntilLighter(
    const Eigen::Isometry3d& X_BinTcpFrom, const Eigen::Isometry3d& X_BinTcpTo,
    const devices::WrenchReading& reference, double below, const char* unsettled_key, Attempt& attempt) {
  for (const Eigen::Isometry3d& X_BinTcpStep :
       DescentSteps(params_.put_back_step, X_BinTcpFrom, X_BinTcpTo)) {
    MoveTo(X_BinTcpStep, params_.lift_speed, &attempt);
    double weight = 0.0;
    try {
      weight =
          PayloadOnTool(devices::AsWrench(reference), devices::AsWrench(ReadWrench()), X_BinTcpStep.linear())
              .weight;
    } catch (const CellFault& fault) {
      if (!detail::ReadingsDisagree(fault)) throw;
      // A tangle whose arms touch the heap swings and slides: readings that disagree say nothing
      // of where it rests. Letting it go there dropped three trees out of a simulated bin.
      attempt.record["wrench"][unsettled_key].push_back(X_BinTcpStep.translation().z());
      continue;
    }
    if (weight < below) return Lighter{X_BinTcpStep, weight};
  }
  if (X_BinTcpTo.translation().z() < X_BinTcpFrom.translation().z() - detail::kSameHeight)
    MoveTo(X_BinTcpTo, params_.lift_speed, &attempt);
  return std::nullopt;
}

Eigen::Isometry3d CellController::LayDown(const Eigen::Isometry3d& X_BinTcpFrom,
                                          const Eigen::Isometry3d& X_BinTcpRelease,
                                          const devices::WrenchReading& reference, Attempt& attempt) {
  const std::optional<Lighter> rest = DescendUntilLighter(X_BinTcpFrom, X_BinTcpRelease, reference,
                                                          0.5 * TubeWeight(), "put_back_unsettled", attempt);
  if (!rest) return X_BinTcpRelease;
  const double above = rest->X_BinTcp.translation().z() - X_BinTcpRelease.translation().z();
  attempt.record["put_back_touchdown"] = {{"above_release", above}, {"load", rest->load}};
  spdlog::info(
      "cell: round {}: the tubes put back rest on the heap {:.3f} m above the release height "
      "({:.2f} N still hang on the tool, under half a tube's weight): opening there",
      round_, above, rest->load);
  return rest->X_BinTcp;
}

void CellController::CheckToolEmpty(const devices::WrenchReading& reference, const std::string& key,
                                    const Eigen::Isometry3d& X_BinTcpShed, Attempt& attempt) {
  auto load_now = [&](const std::string& name) {
    const devices::WrenchReading reading = ReadWrench();
    attempt.record["wrench"][name] = WrenchJson(reading);
    return LoadOnTool(reference, reading);
  };
  std::optional<double> load = load_now(key);
  if (!load) return;
  const bool placing = state_ == CellState::kPlace;
  const char* lowered = placing ? "onto the place pose" : "into the bin";
  spdlog::warn("cell: round {}: {:.2f} N on the tool after it let go ({}): lowering it {} once", round_,
               *load, key, lowered);
  const Eigen::Isometry3d X_BinTcpUp = CurrentPose();
  MoveTo(X_BinTcpShed, params_.approach_speed, &attempt);
  MoveTo(X_BinTcpUp, params_.approach_speed, &attempt);
  load = load_now(key + "_again");
  if (!load) return;
  held_ = Held::kUnknown;
  caught_reference_ = reference;
  // What still hangs on the tool is (part of) the tube the place let go: not placed.
  if (placing) attempt.record["placed"] = false;
  const double tube_weight = TubeWeight();
  const Eigen::Vector3d p = X_BinTcpUp.translation();
  throw CellFault("ft_sensor", FaultKind::kUnexpectedLoad, ToString(state_),
                  fmt::format("the tool carries {:.2f} N ({:.1f} times a tube's weight) after letting go, at "
                              "X_BinTcp ({:.3f}, {:.3f}, {:.3f}) m, also after lowering it {} once: a "
                              "tube caught on the pads or the housing?",
                              *load, *load / tube_weight, p.x(), p.y(), p.z(), lowered));
}

double CellController::TubeWeight() const {
  return cell_.tube.mass * ProfileWrenchParams(params_.profile).gravity;
}

std::optional<double> CellController::LoadOnTool(const devices::WrenchReading& reference,
                                                 const devices::WrenchReading& now) const {
  const double load = (now.force - reference.force).norm();
  if (load <= ProfileWrenchParams(params_.profile).force_tolerance) return std::nullopt;
  return load;
}

void CellController::ExecuteNudge(const NudgePlan& plan, Attempt& attempt) {
  Enter(CellState::kNudge);
  // The fingers move only above the walls: closed before the tool goes down, opened after it is
  // back up. In a heap as high as the walls, fingers opening at the approach height sweep 5 cm
  // sideways into whatever lies there (seen in the simulated cell: 230 N on the two pads).
  CloseGripper();
  Eigen::Isometry3d X_BinTcpAbovePress = plan.X_BinTcpPress;
  X_BinTcpAbovePress.translation().z() += params_.approach_height;
  TransitTo(X_BinTcpAbovePress, &attempt);
  // The reference with the pads closed, as they stay until the check after the push.
  const devices::WrenchReading reference = ReadWrench();
  attempt.record["wrench"] = {{"reference", WrenchJson(reference)}};
  MoveTo(plan.X_BinTcpPress, params_.approach_speed, &attempt);
  MoveThrough(NudgePushWaypoints(plan), params_.nudge.speed, &attempt);
  const Eigen::Isometry3d X_BinTcpPushed = CurrentPose();
  MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, params_.approach_height)},
              params_.approach_speed, &attempt);
  // A hose can hook over a pad while it is pushed: it must not ride home.
  CheckToolEmpty(reference, "after_nudge", X_BinTcpPushed, attempt);
  OpenAboveTheWalls(&attempt);
  GoHome(&attempt);
}

/// Straight up to the transit height (if lower), then open: over the bin, clear of the heap.
void CellController::OpenAboveTheWalls(Attempt* attempt) {
  const Eigen::Isometry3d X_BinTcp = CurrentPose();
  const double transit_height = TransitHeight(params_, cell_);
  if (X_BinTcp.translation().z() < transit_height)
    MoveTo(WithHeight(X_BinTcp, transit_height), params_.approach_speed, attempt);
  OpenGripper();
}

void CellController::GoHome(Attempt* attempt) {
  Enter(CellState::kHome);
  const Eigen::Isometry3d X_BinHome = HomePose(params_, cell_);
  TransitTo(X_BinHome, attempt);
}

}  // namespace tubepick::cell
