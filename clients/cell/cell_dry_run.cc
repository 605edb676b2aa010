// The dry run: scan and plan once, then list the commands the best executable plan would give,
// without giving any (no servo on, no robot motion, no gripper command).

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "clients/cell/attempt_record.h"
#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_controller_internal.h"

namespace tubepick::cell {
namespace {

std::string FormatPose(const Eigen::Isometry3d& X) {
  const Eigen::Vector3d p = X.translation();
  const Eigen::Quaterniond q(X.rotation());
  return fmt::format("({:.3f}, {:.3f}, {:.3f}) m, q_xyzw ({:.3f}, {:.3f}, {:.3f}, {:.3f})", p.x(), p.y(),
                     p.z(), q.x(), q.y(), q.z(), q.w());
}

std::string FormatMotion(const PlannedMotion& m) {
  switch (m.kind) {
    case MotionKind::kTransit: {
      std::string via;
      for (const Eigen::Isometry3d& X : m.via) {
        const Eigen::Vector3d p = X.translation();
        via += fmt::format("{}({:.3f}, {:.3f}, {:.3f})", via.empty() ? " via " : ", ", p.x(), p.y(), p.z());
      }
      return fmt::format("to {} at {:.3f} m/s{}", FormatPose(m.X_BinTcp), m.speed, via);
    }
    case MotionKind::kMoveTo:
      return fmt::format("to {} at {:.3f} m/s", FormatPose(m.X_BinTcp), m.speed);
    case MotionKind::kMoveThrough:
      return fmt::format("{} waypoints to {} at {:.3f} m/s", m.waypoints_Bin.size(), FormatPose(m.X_BinTcp),
                         m.speed);
    case MotionKind::kGripperMoveTo:
      return fmt::format("to {:.1f} mm at {:.3f} m/s, {:.0f} N", m.gripper_opening.value_or(0.0) * 1e3,
                         m.speed, m.gripper_force.value_or(0.0));
    case MotionKind::kGripperClose:
      return fmt::format("at {:.3f} m/s, {:.0f} N", m.speed, m.gripper_force.value_or(0.0));
    case MotionKind::kGripperOpen:
      return "fully";
  }
  return "";
}

}  // namespace

using detail::CallDevice;
using detail::CellMismatchMessage;

std::vector<PlannedMotion> CellController::PlannedMotions(const PlanPoses& poses,
                                                          double opening_width) const {
  std::vector<PlannedMotion> motions;
  const auto robot = [&](MotionKind kind, CellState state, const char* step,
                         const Eigen::Isometry3d& X_BinTcp, double speed) -> PlannedMotion& {
    PlannedMotion& m = motions.emplace_back();
    m.kind = kind;
    m.state = state;
    m.step = step;
    m.X_BinTcp = X_BinTcp;
    m.speed = speed;
    return m;
  };
  const auto transit = [&](CellState state, const char* step, const Eigen::Isometry3d& X_BinTcpFrom,
                           const Eigen::Isometry3d& X_BinTcpTo) {
    std::vector<Eigen::Isometry3d> segments = TransitSegments(X_BinTcpFrom, X_BinTcpTo);
    PlannedMotion& m = robot(MotionKind::kTransit, state, step, segments.back(), params_.transit_speed);
    segments.pop_back();
    m.via = std::move(segments);
  };
  const auto gripper = [&](MotionKind kind, CellState state, const char* step,
                           const Eigen::Isometry3d& X_BinTcp, double speed, std::optional<double> opening,
                           std::optional<double> force) {
    PlannedMotion& m = robot(kind, state, step, X_BinTcp, speed);
    m.gripper_opening = opening;
    m.gripper_force = force;
  };

  // As ExecutePlan → Approach, Grasp, Lift, Place (one tube held), GoHome; every attempt starts at home.
  const Eigen::Isometry3d X_BinHome = HomePose(params_, cell_);
  transit(CellState::kApproach, "transit to the pre-grasp pose", X_BinHome, poses.X_BinTcpPreGrasp);
  if (opening_width > 0.0)
    gripper(MotionKind::kGripperMoveTo, CellState::kApproach, "open to the grasp width",
            poses.X_BinTcpPreGrasp, params_.gripper_speed, opening_width, params_.gripper_force);
  robot(MotionKind::kMoveTo, CellState::kGrasp, "down to the grasp pose", poses.X_BinTcpGrasp,
        params_.approach_speed);
  gripper(MotionKind::kGripperClose, CellState::kGrasp, "close on the tube", poses.X_BinTcpGrasp,
          params_.gripper_speed, std::nullopt, params_.gripper_force);
  Eigen::Isometry3d X_BinTcpLift = poses.X_BinTcpGrasp;
  X_BinTcpLift.translation() += poses.waypoints_Bin.back();
  robot(MotionKind::kMoveThrough, CellState::kLift, "lift along the plan's waypoints", X_BinTcpLift,
        params_.lift_speed)
      .waypoints_Bin = poses.waypoints_Bin;
  // As Place: the planned pose raised where the closed tool would touch the place surface.
  const Eigen::Isometry3d X_BinTcpPlace =
      PlacePoseClearOfTheSurface(params_, cell_.tube.radius, poses.X_BinTcpPlace);
  Eigen::Isometry3d X_BinTcpAbovePlace = X_BinTcpPlace;
  X_BinTcpAbovePlace.translation().z() += params_.place_approach_height;
  transit(CellState::kPlace, "transit above the place pose", X_BinTcpLift, X_BinTcpAbovePlace);
  robot(MotionKind::kMoveTo, CellState::kPlace, "down to the place pose (opens where the tube rests)",
        X_BinTcpPlace, params_.approach_speed)
      .via = PlaceDescentSteps(params_, X_BinTcpAbovePlace, X_BinTcpPlace);
  gripper(MotionKind::kGripperOpen, CellState::kPlace, "open: the tube is placed", X_BinTcpPlace, 0.0,
          std::nullopt, std::nullopt);
  robot(MotionKind::kMoveTo, CellState::kPlace, "back up above the place pose", X_BinTcpAbovePlace,
        params_.approach_speed);
  transit(CellState::kHome, "home", X_BinTcpAbovePlace, X_BinHome);
  return motions;
}

DryRunResult CellController::DryRun(std::uint32_t round) {
  round_ = round;
  stopping_ = false;
  commanded_ = false;
  dry_run_ = true;
  held_ = Held::kUnknown;
  DryRunResult dry;
  RunState run;
  PlannedScan scan;
  CellRunResult& result = run.result;
  const std::optional<StopCause> cause = Guarded([&] {
    Enter(CellState::kStart);
    // Read only: where the arm is and what the gripper says.
    dry.X_BinTcpStart = CurrentPose();
    const devices::GripperStatus status = CheckGripper(
        CallDevice("gripper", state_, [&] { return devices_.gripper->Status(params_.gripper_timeout); }));
    dry.gripper = status;
    held_ = status.object == devices::GripperObject::kStoppedClosing ? Held::kTube : Held::kNothing;
    const std::string holding_note =
        held_ == Held::kTube
            ? "; the gripper reports an object: a run opens it at its start, where the arm is"
            : "";

    scan = ScanBin(run);
    const v1::PlanPickResponse& response = scan.response;
    if (response.bin_empty()) {
      dry.bin_empty = true;
      result.reason = CellStopReason::kBinEmpty;
      result.message = fmt::format("dry run: bin empty; nothing moved{}", holding_note);
      return;
    }
    result.reason = CellStopReason::kDryRun;
    for (int rank = 0; rank < response.plans_size(); ++rank) {
      const v1::PickPlan& plan = response.plans(rank);
      if (const std::optional<PlanSkip> skip = ExecutionProblem(response, rank)) {
        scan.skipped.push_back(SkippedPlanJson(rank, plan.tube_id(), skip->check, skip->reason));
        if (skip->check == "cell_frame" && scan.cell_mismatches++ == 0)
          scan.first_cell_mismatch = skip->reason;
        continue;
      }
      const PlanPoses poses = PosesOf(plan, rank);
      dry.motions = PlannedMotions(poses, plan.grasp().opening_width());
      dry.plan_rank = static_cast<std::uint32_t>(rank);
      dry.tube = plan.tube_id();
      result.message = fmt::format("dry run: plan {} (tube {}) of {}: {} commands planned, nothing moved{}{}",
                                   rank, plan.tube_id(), response.plans_size(), dry.motions.size(),
                                   rank > 0 ? fmt::format(" ({} plans skipped)", rank) : "", holding_note);
      return;
    }
    if (response.plans_size() > 0 &&
        scan.cell_mismatches == static_cast<std::uint32_t>(response.plans_size()))
      dry.cell_mismatch = CellMismatchMessage(scan.cell_mismatches, scan.first_cell_mismatch);
    result.message = fmt::format(
        "dry run: no executable plan ({} plans, {} tubes modeled){}; nothing moved{}", response.plans_size(),
        response.tubes_size(), dry.cell_mismatch ? ": " + *dry.cell_mismatch : "", holding_note);
  });
  if (cause) SafeStop(*cause, result);
  dry.run = result;
  dry.skipped_plans = scan.skipped;
  spdlog::info("cell: {}", result.message);
  if (sink_) {
    nlohmann::json record = {
        {"type", "dry_run"}, {"round", round}, {"scan", scan.index}, {"seed", params_.seed}};
    record.update(DryRunJson(dry));
    sink_->Write(record);
  }
  dry_run_ = false;
  return dry;
}

std::string FormatDryRun(const DryRunResult& dry) {
  std::string text = dry.run.message + "\n";
  if (dry.X_BinTcpStart) text += fmt::format("robot at X_BinTcp {}\n", FormatPose(*dry.X_BinTcpStart));
  if (dry.gripper)
    text += fmt::format("gripper: {}, fingers at {:.1f} mm\n", GripperObjectName(dry.gripper->object),
                        dry.gripper->opening * 1e3);
  for (const nlohmann::json& skipped : dry.skipped_plans)
    text += fmt::format("skipped plan {} (tube {}): {}\n", skipped.value("rank", -1),
                        skipped.value("tube", 0u), skipped.value("reason", ""));
  for (std::size_t i = 0; i < dry.motions.size(); ++i) {
    const PlannedMotion& m = dry.motions[i];
    text += fmt::format("{:>3}. {:<9} {:<16} {}: {}\n", i + 1, ToString(m.state), ToString(m.kind), m.step,
                        FormatMotion(m));
  }
  return text;
}

nlohmann::json DryRunJson(const DryRunResult& dry) {
  nlohmann::json motions = nlohmann::json::array();
  for (const PlannedMotion& m : dry.motions) motions.push_back(PlannedMotionJson(m));
  return {{"reason", ToString(dry.run.reason)},
          {"message", dry.run.message},
          {"bin_empty", dry.bin_empty},
          {"plan_rank", dry.plan_rank ? nlohmann::json(*dry.plan_rank) : nlohmann::json()},
          {"tube", dry.tube},
          {"skipped_plans", dry.skipped_plans},
          {"cell_mismatch", dry.cell_mismatch ? nlohmann::json(*dry.cell_mismatch) : nlohmann::json()},
          {"robot_pose", dry.X_BinTcpStart ? PoseJson(*dry.X_BinTcpStart) : nlohmann::json()},
          {"gripper", dry.gripper ? GripperJson(*dry.gripper) : nlohmann::json()},
          {"motions", motions}};
}

}  // namespace tubepick::cell
