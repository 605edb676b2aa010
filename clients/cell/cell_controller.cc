#include "clients/cell/cell_controller.h"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "wire/proto_convert.h"
#include "core/common/errors.h"
#include "wire/packed_cloud.h"

namespace tubepick::cell {
namespace {

using Clock = std::chrono::steady_clock;

/// The plan's unit approach direction; the TCP's z axis when the plan gives none.
Eigen::Vector3d ApproachOf(const v1::PickPlan& plan, const Eigen::Isometry3d& X_grasp) {
  Eigen::Vector3d approach = FromProto(plan.grasp().approach());
  if (!approach.allFinite() || approach.norm() < 1e-9) approach = X_grasp.linear().col(2);
  return approach.normalized();
}

/// The grasp pose backed off `height` against the approach direction.
Eigen::Isometry3d PreGraspPose(const Eigen::Isometry3d& X_grasp, const Eigen::Vector3d& approach,
                               double height) {
  Eigen::Isometry3d X_pre = X_grasp;
  X_pre.translation() -= height * approach;
  return X_pre;
}

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

nlohmann::json Vec(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

Eigen::Isometry3d WithHeight(Eigen::Isometry3d X, double z) {
  X.translation().z() = z;
  return X;
}

constexpr double kSameHeight = 1e-4;  // m: moves shorter than this are skipped

}  // namespace

std::string ToString(CellState state) {
  switch (state) {
    case CellState::kStart:
      return "start";
    case CellState::kBias:
      return "bias";
    case CellState::kScan:
      return "scan";
    case CellState::kPlan:
      return "plan";
    case CellState::kApproach:
      return "approach";
    case CellState::kReference:
      return "reference";
    case CellState::kGrasp:
      return "grasp";
    case CellState::kLift:
      return "lift";
    case CellState::kAnalyze:
      return "analyze";
    case CellState::kPlace:
      return "place";
    case CellState::kResolve:
      return "resolve";
    case CellState::kReturnToBin:
      return "return_to_bin";
    case CellState::kNudge:
      return "nudge";
    case CellState::kRelease:
      return "release";
    case CellState::kHome:
      return "home";
    case CellState::kSafeStop:
      return "safe_stop";
  }
  return "unknown";
}

std::string ToString(CellStopReason reason) {
  switch (reason) {
    case CellStopReason::kBinEmpty:
      return "bin_empty";
    case CellStopReason::kLimitReached:
      return "limit_reached";
    case CellStopReason::kFault:
      return "fault";
  }
  return "fault";
}

/// One picking attempt under way: its record and its running durations.
struct CellController::Attempt {
  nlohmann::json record;
  double robot_wall_s = 0.0;
  double robot_device_s = 0.0;
  double analysis_wall_s = 0.0;
  Clock::time_point started = Clock::now();
  double device_started = 0.0;
  std::optional<AttemptResult> result;
};

namespace {

/// Runs a device call; its DeviceTimeout / DeviceFault become a CellFault naming the device.
template <typename F>
auto CallDevice(const char* device, CellState state, F&& call) -> decltype(call()) {
  try {
    return call();
  } catch (const devices::DeviceTimeout& e) {
    throw CellFault(device, FaultKind::kTimeout, ToString(state), e.what());
  } catch (const devices::DeviceFault& e) {
    throw CellFault(device, FaultKind::kDeviceFault, ToString(state), e.what());
  }
}

/// Runs a planner call; a PlannerError becomes a CellFault.
template <typename F>
auto CallPlanner(CellState state, F&& call) -> decltype(call()) {
  try {
    return call();
  } catch (const PlannerError& e) {
    const bool unavailable = e.code() == grpc::StatusCode::UNAVAILABLE ||
                             e.code() == grpc::StatusCode::RESOURCE_EXHAUSTED ||
                             e.code() == grpc::StatusCode::DEADLINE_EXCEEDED;
    throw CellFault("planner", unavailable ? FaultKind::kServerUnavailable : FaultKind::kServerError,
                    ToString(state), e.what());
  }
}

const char* ResultName(int result) {
  static const char* const kNames[] = {"picked", "multiple_returned", "none", "grasp_failed"};
  return kNames[result];
}

}  // namespace

CellController::CellController(CellDevices devices, PlannerClient& planner, CellConfig cell,
                               CellControllerParams params, RecordSink* sink)
    : devices_(devices), planner_(planner), cell_(std::move(cell)), params_(std::move(params)), sink_(sink) {
  if (!devices_.scanner || !devices_.robot || !devices_.gripper || !devices_.ft_sensor)
    throw InvalidArgument("cell controller devices: scanner, robot, gripper and ft_sensor are all required");
  cell_.Validate();
  params_.Validate();
}

void CellController::Enter(CellState state) {
  state_ = state;
  spdlog::debug("cell: {}", ToString(state));
}

double CellController::DeviceNow() const { return device_clock_ ? device_clock_() : 0.0; }

nlohmann::json CellController::Truth() const { return annotator_ ? annotator_() : nlohmann::json(); }

// ---------------------------------------------------------------- devices

devices::Capture CellController::Scan() {
  return CallDevice("scanner", state_, [&] { return devices_.scanner->Scan(params_.scanner_timeout); });
}

template <typename Motion>
void CellController::TimedRobotMotion(Attempt* attempt, const Motion& motion) {
  const Clock::time_point start = Clock::now();
  const double device_start = DeviceNow();
  CallDevice("robot", state_, motion);
  if (attempt) {
    attempt->robot_wall_s += SecondsSince(start);
    attempt->robot_device_s += DeviceNow() - device_start;
  }
}

void CellController::MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Attempt* attempt) {
  TimedRobotMotion(attempt, [&] { devices_.robot->MoveTo(X_BinTcp, speed, params_.robot_timeout); });
}

void CellController::MoveThrough(const std::vector<Eigen::Vector3d>& waypoints, double speed,
                                 Attempt* attempt) {
  TimedRobotMotion(attempt, [&] { devices_.robot->MoveThrough(waypoints, speed, params_.robot_timeout); });
}

Eigen::Isometry3d CellController::CurrentPose() {
  return CallDevice("robot", state_, [&] { return devices_.robot->CurrentPose(params_.robot_timeout); });
}

void CellController::TransitTo(const Eigen::Isometry3d& X_BinTcp, Attempt* attempt) {
  const Eigen::Isometry3d X_now = CurrentPose();
  const double z_transit =
      std::max({TransitHeight(params_, cell_), X_now.translation().z(), X_BinTcp.translation().z()});
  if (X_now.translation().z() < z_transit - kSameHeight)
    MoveTo(WithHeight(X_now, z_transit), params_.transit_speed, attempt);
  MoveTo(WithHeight(X_BinTcp, z_transit), params_.transit_speed, attempt);
  if (X_BinTcp.translation().z() < z_transit - kSameHeight) MoveTo(X_BinTcp, params_.transit_speed, attempt);
}

devices::GripperStatus CellController::CheckGripper(const devices::GripperStatus& status) {
  if (status.fault != 0)
    throw CellFault("gripper", FaultKind::kDeviceFault, ToString(state_),
                    fmt::format("fault 0x{:02X}: {}", status.fault,
                                status.fault_text.empty() ? "(no description)" : status.fault_text));
  return status;
}

void CellController::OpenGripper() {
  CheckGripper(
      CallDevice("gripper", state_, [&] { return devices_.gripper->Open(params_.gripper_timeout); }));
}

devices::WrenchReading CellController::ReadWrench() {
  for (std::uint32_t i = 0; i < params_.ft_settle_samples; ++i)
    CallDevice("ft_sensor", state_, [&] { return devices_.ft_sensor->Read(params_.ft_timeout); });
  devices::WrenchReading mean;
  for (std::uint32_t i = 0; i < params_.ft_samples; ++i) {
    const devices::WrenchReading r =
        CallDevice("ft_sensor", state_, [&] { return devices_.ft_sensor->Read(params_.ft_timeout); });
    mean.force += r.force;
    mean.torque += r.torque;
    mean.sequence = r.sequence;
  }
  mean.force /= params_.ft_samples;
  mean.torque /= params_.ft_samples;
  return mean;
}

v1::AnalyzeWrenchResponse CellController::Analyze(const devices::WrenchReading& reference,
                                                  const devices::WrenchReading& current,
                                                  const Eigen::Isometry3d& X_lift, Attempt& attempt) {
  v1::AnalyzeWrenchRequest request;
  *request.mutable_reference() = ToProto(Wrench{reference.force, reference.torque});
  *request.mutable_current() = ToProto(Wrench{current.force, current.torque});
  request.set_tube_mass(cell_.tube.mass);
  *request.mutable_tcp_pose() = ToProto(X_lift);
  request.set_variant(params_.resolution_variant);
  const Clock::time_point start = Clock::now();
  v1::AnalyzeWrenchResponse response =
      CallPlanner(state_, [&] { return planner_.AnalyzeWrench(request, params_.analyze_deadline); });
  attempt.analysis_wall_s += SecondsSince(start);
  if (response.outcome() != v1::HELD_OUTCOME_NONE && response.outcome() != v1::HELD_OUTCOME_SINGLE &&
      response.outcome() != v1::HELD_OUTCOME_MULTIPLE)
    throw CellFault("planner", FaultKind::kServerError, ToString(state_),
                    fmt::format("AnalyzeWrench answered outcome {}", static_cast<int>(response.outcome())));
  return response;
}

std::optional<std::string> CellController::ClearanceProblem(const v1::PickPlan& plan, int rank) const {
  Eigen::Isometry3d X_grasp;
  try {
    X_grasp = FromProto(plan.grasp().tcp_pose(), fmt::format("plans[{}].grasp.tcp_pose", rank));
  } catch (const InvalidArgument& e) {
    throw CellFault("planner", FaultKind::kServerError, ToString(state_), e.what());
  }
  std::vector<Eigen::Vector3d> waypoints;
  for (const v1::Vector3& w : plan.waypoints()) waypoints.push_back(FromProto(w));
  // The arm's reach and wrist limits: pre-grasp, grasp, every lift waypoint and the placement.
  const devices::RobotLimits limits = devices_.robot->Limits();
  std::vector<std::pair<std::string, Eigen::Isometry3d>> poses;
  poses.emplace_back("pre-grasp", PreGraspPose(X_grasp, ApproachOf(plan, X_grasp), params_.approach_height));
  poses.emplace_back("grasp", X_grasp);
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    Eigen::Isometry3d X = X_grasp;
    X.translation() += waypoints[i];
    poses.emplace_back(fmt::format("waypoint {}", i), X);
  }
  if (plan.has_place_tcp_pose()) {
    try {
      poses.emplace_back("place",
                         FromProto(plan.place_tcp_pose(), fmt::format("plans[{}].place_tcp_pose", rank)));
    } catch (const InvalidArgument& e) {
      throw CellFault("planner", FaultKind::kServerError, ToString(state_), e.what());
    }
  }
  for (const auto& [what, X] : poses) {
    const std::string problem = limits.Problem(X);
    if (!problem.empty()) return fmt::format("robot limits at the {}: {}", what, problem);
  }
  if (!params_.check_tool_clearance) return std::nullopt;
  return ToolClearanceProblem(cell_, params_.tool, X_grasp, plan.grasp().opening_width(), waypoints);
}

// ---------------------------------------------------------------- cycle

void CellController::StartCell() {
  Enter(CellState::kStart);
  CallDevice("robot", state_, [&] { devices_.robot->ServoOn(params_.robot_timeout); });
  CallDevice("gripper", state_, [&] { devices_.gripper->Activate(params_.gripper_timeout); });
  OpenGripper();
  Enter(CellState::kHome);
  TransitTo(HomePose(params_, cell_), nullptr);
  Enter(CellState::kBias);
  CallDevice("ft_sensor", state_, [&] { devices_.ft_sensor->Bias(params_.ft_timeout); });
}

void CellController::ExecutePlan(const v1::PlanPickResponse& response, int plan_index, Attempt& attempt) {
  const v1::PickPlan& plan = response.plans(plan_index);
  nlohmann::json& rec = attempt.record;
  rec["tube"] = plan.tube_id();
  rec["trajectory_kind"] = TrajectoryKindName(plan.trajectory_kind());
  rec["cost"] = {{"height", plan.cost().height()},
                 {"centre", plan.cost().centre()},
                 {"trajectory", plan.cost().trajectory()},
                 {"total", plan.cost().total()}};
  rec["simulated_displacement"] = plan.simulated_displacement();

  const std::string field = fmt::format("plans[{}]", plan_index);
  Eigen::Isometry3d X_grasp, X_place;
  try {
    X_grasp = FromProto(plan.grasp().tcp_pose(), field + ".grasp.tcp_pose");
    X_place = FromProto(plan.place_tcp_pose(), field + ".place_tcp_pose");
  } catch (const InvalidArgument& e) {
    throw CellFault("planner", FaultKind::kServerError, ToString(CellState::kPlan), e.what());
  }
  if (plan.waypoints_size() == 0)
    throw CellFault("planner", FaultKind::kServerError, ToString(CellState::kPlan),
                    field + ".waypoints: empty (a trajectory starts with (0, 0, 0))");
  const Eigen::Vector3d approach = ApproachOf(plan, X_grasp);
  rec["grasp"] = {{"tcp_pose", PoseJson(X_grasp)},
                  {"approach", Vec(approach)},
                  {"opening_width", plan.grasp().opening_width()}};

  // Approach: transit to the pre-grasp pose, open to the grasp width.
  Enter(CellState::kApproach);
  const Eigen::Isometry3d X_pre = PreGraspPose(X_grasp, approach, params_.approach_height);
  TransitTo(X_pre, &attempt);
  if (plan.grasp().opening_width() > 0.0) {
    CheckGripper(CallDevice("gripper", state_, [&] {
      return devices_.gripper->MoveTo(plan.grasp().opening_width(), params_.gripper_speed,
                                      params_.gripper_force, params_.gripper_timeout);
    }));
  }

  // Reference: the gripper is empty and already in the orientation of the lift.
  Enter(CellState::kReference);
  const devices::WrenchReading reference = ReadWrench();
  rec["wrench"] = {{"reference", WrenchJson(reference)}};

  // Grasp and check the gripper's object status.
  Enter(CellState::kGrasp);
  MoveTo(X_grasp, params_.approach_speed, &attempt);
  const devices::GripperStatus closed = CheckGripper(CallDevice("gripper", state_, [&] {
    return devices_.gripper->Close(params_.gripper_speed, params_.gripper_force, params_.gripper_timeout);
  }));
  rec["gripper"] = GripperJson(closed);
  if (closed.object != devices::GripperObject::kStoppedClosing) {
    Enter(CellState::kRelease);
    OpenGripper();
    MoveTo(X_pre, params_.approach_speed, &attempt);
    Enter(CellState::kHome);
    TransitTo(HomePose(params_, cell_), &attempt);
    attempt.result = AttemptResult::kGraspFailed;
    return;
  }

  // Lift along the plan's trajectory.
  Enter(CellState::kLift);
  std::vector<Eigen::Vector3d> waypoints;
  for (const v1::Vector3& w : plan.waypoints()) waypoints.push_back(FromProto(w));
  MoveThrough(waypoints, params_.lift_speed, &attempt);
  const Eigen::Isometry3d X_lift = CurrentPose();

  Enter(CellState::kAnalyze);
  const devices::WrenchReading lifted = ReadWrench();
  rec["wrench"]["lift"] = WrenchJson(lifted);
  rec["wrench"]["after_resolution"] = nlohmann::json::array();
  const v1::AnalyzeWrenchResponse analysis = Analyze(reference, lifted, X_lift, attempt);
  rec["analysis"] = {{"outcome", HeldOutcomeName(analysis.outcome())},
                     {"estimated_count", analysis.estimated_count()},
                     {"tube_ratio", analysis.tube_ratio()},
                     {"held_weight", analysis.held_weight()},
                     {"tube_weight", analysis.tube_weight()},
                     {"motions", analysis.resolution_motions_size()}};
  rec["resolution"] = {{"available", analysis.resolution_motions_size()}, {"used", 0}, {"succeeded", false}};

  switch (analysis.outcome()) {
    case v1::HELD_OUTCOME_SINGLE:
      Place(X_place, attempt);
      attempt.result = AttemptResult::kPicked;
      return;
    case v1::HELD_OUTCOME_NONE:
      Enter(CellState::kRelease);
      OpenGripper();
      Enter(CellState::kHome);
      TransitTo(HomePose(params_, cell_), &attempt);
      attempt.result = AttemptResult::kNone;
      return;
    default:
      break;
  }

  // Several tubes: resolution motions in order, each followed by a new reading at the lift pose.
  Enter(CellState::kResolve);
  for (int m = 0; m < analysis.resolution_motions_size(); ++m) {
    const v1::ResolutionMotion& motion = analysis.resolution_motions(m);
    rec["resolution"]["used"] = m + 1;
    for (int w = 0; w < motion.waypoints_size(); ++w) {
      Eigen::Isometry3d X_wp;
      try {
        X_wp = FromProto(motion.waypoints(w).tcp_pose(),
                        fmt::format("resolution_motions[{}].waypoints[{}].tcp_pose", m, w));
      } catch (const InvalidArgument& e) {
        throw CellFault("planner", FaultKind::kServerError, ToString(state_), e.what());
      }
      MoveTo(X_wp, params_.resolution_speed, &attempt);
    }
    MoveTo(X_lift, params_.resolution_speed, &attempt);
    const devices::WrenchReading after = ReadWrench();
    const v1::AnalyzeWrenchResponse again = Analyze(reference, after, X_lift, attempt);
    rec["wrench"]["after_resolution"].push_back({{"motion", m},
                                                 {"description", motion.description()},
                                                 {"wrench", WrenchJson(after)},
                                                 {"outcome", HeldOutcomeName(again.outcome())},
                                                 {"tube_ratio", again.tube_ratio()}});
    if (again.outcome() == v1::HELD_OUTCOME_SINGLE) {
      rec["resolution"]["succeeded"] = true;
      Place(X_place, attempt);
      attempt.result = AttemptResult::kPicked;
      return;
    }
    if (again.outcome() == v1::HELD_OUTCOME_NONE) {
      Enter(CellState::kRelease);
      OpenGripper();
      Enter(CellState::kHome);
      TransitTo(HomePose(params_, cell_), &attempt);
      attempt.result = AttemptResult::kNone;
      return;
    }
  }
  ReturnToBin(X_grasp, X_lift, attempt);
  attempt.result = AttemptResult::kMultipleReturned;
}

void CellController::Place(const Eigen::Isometry3d& X_place, Attempt& attempt) {
  Enter(CellState::kPlace);
  Eigen::Isometry3d X_above = X_place;
  X_above.translation().z() += params_.place_approach_height;
  TransitTo(X_above, &attempt);
  MoveTo(X_place, params_.approach_speed, &attempt);
  OpenGripper();
  MoveTo(X_above, params_.approach_speed, &attempt);
  Enter(CellState::kHome);
  TransitTo(HomePose(params_, cell_), &attempt);
}

void CellController::ExecuteNudge(const NudgePlan& plan, Attempt& attempt) {
  Enter(CellState::kNudge);
  // Closed pads (nothing between them: the gripper is at home) make one narrow block.
  CheckGripper(CallDevice("gripper", state_, [&] {
    return devices_.gripper->Close(params_.gripper_speed, params_.gripper_force, params_.gripper_timeout);
  }));
  Eigen::Isometry3d X_above = plan.X_BinTcp_press;
  X_above.translation().z() += params_.approach_height;
  TransitTo(X_above, &attempt);
  MoveTo(plan.X_BinTcp_press, params_.approach_speed, &attempt);
  MoveThrough(NudgePushWaypoints(plan), params_.nudge.speed, &attempt);
  MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, params_.approach_height)},
              params_.approach_speed, &attempt);
  OpenGripper();
  Enter(CellState::kHome);
  TransitTo(HomePose(params_, cell_), &attempt);
}

void CellController::ReturnToBin(const Eigen::Isometry3d& X_grasp, const Eigen::Isometry3d& X_lift,
                                 Attempt& attempt) {
  Enter(CellState::kReturnToBin);
  // Straight down from the lift pose (its xy was checked against the bin's safety zone by the
  // planner) to just above the grasp height, open, and back up.
  const double drop = X_grasp.translation().z() + params_.release_height - X_lift.translation().z();
  if (drop < 0.0)
    MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, drop)}, params_.lift_speed, &attempt);
  OpenGripper();
  if (drop < 0.0)
    MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, -drop)}, params_.approach_speed, &attempt);
  Enter(CellState::kHome);
  TransitTo(HomePose(params_, cell_), &attempt);
}

void CellController::SafeStop(const CellFault& fault, CellRunResult& result) {
  Enter(CellState::kSafeStop);
  spdlog::error("cell: {}", fault.what());
  std::string gripper_note, robot_note;
  try {
    const devices::GripperStatus status = devices_.gripper->Open(params_.gripper_timeout);
    result.gripper_opened = status.fault == 0;
    gripper_note = result.gripper_opened ? "gripper opened"
                                         : fmt::format("gripper could not be opened (fault 0x{:02X}: {})",
                                                       status.fault, status.fault_text);
  } catch (const std::exception& e) {
    gripper_note = fmt::format("gripper could not be opened ({})", e.what());
  }
  try {
    Eigen::Isometry3d X = devices_.robot->CurrentPose(params_.robot_timeout);
    const double z_safe = TransitHeight(params_, cell_);
    if (X.translation().z() < z_safe - kSameHeight) {
      devices_.robot->MoveTo(WithHeight(X, z_safe), params_.transit_speed, params_.robot_timeout);
      robot_note = fmt::format("robot moved up to z = {:.3f} m", z_safe);
    } else {
      robot_note = fmt::format("robot already at a safe height (z = {:.3f} m)", X.translation().z());
    }
    result.moved_up = true;
  } catch (const std::exception& e) {
    robot_note = fmt::format("robot could not move up ({})", e.what());
  }
  result.reason = CellStopReason::kFault;
  result.fault = fault;
  result.message =
      fmt::format("SAFE STOP: {} {} during {}: {}; {}; {}", fault.device(), ToString(fault.kind()),
                  fault.state(), fault.error(), gripper_note, robot_note);
  spdlog::error("cell: {}", result.message);
  if (sink_)
    sink_->Write({{"type", "safe_stop"},
                  {"round", round_},
                  {"device", fault.device()},
                  {"kind", ToString(fault.kind())},
                  {"state", fault.state()},
                  {"error", fault.error()},
                  {"gripper_opened", result.gripper_opened},
                  {"moved_up", result.moved_up},
                  {"message", result.message}});
}

CellRunResult CellController::Run(std::uint32_t round) {
  round_ = round;
  CellRunResult result;
  std::uint32_t attempts_since_pick = 0;
  std::uint32_t consecutive_failures = 0;
  std::uint32_t nudges_since_pick = 0;
  std::optional<Attempt> active;
  const nlohmann::json truth_start = Truth();

  const auto limit_reached = [&]() -> std::optional<std::string> {
    if (attempts_since_pick >= params_.max_attempts_per_tube)
      return fmt::format("{} attempts since the last pick (max_attempts_per_tube = {})", attempts_since_pick,
                         params_.max_attempts_per_tube);
    if (result.attempts >= params_.max_attempts_per_bin)
      return fmt::format("{} attempts in this bin (max_attempts_per_bin = {})", result.attempts,
                         params_.max_attempts_per_bin);
    if (consecutive_failures >= params_.max_consecutive_failures)
      return fmt::format("{} consecutive failures (max_consecutive_failures = {})", consecutive_failures,
                         params_.max_consecutive_failures);
    return std::nullopt;
  };

  try {
    try {
      StartCell();
      for (;;) {
        if (const auto why = limit_reached()) {
          result.reason = CellStopReason::kLimitReached;
          result.message = fmt::format("attempt limit reached: {}; {} tubes picked", *why, result.picks);
          break;
        }
        Enter(CellState::kScan);
        const nlohmann::json truth_before = Truth();
        const Clock::time_point scan_start = Clock::now();
        const double scan_device_start = DeviceNow();
        const devices::Capture capture = Scan();
        const std::uint32_t scan = result.scans++;

        Enter(CellState::kPlan);
        v1::PlanPickRequest request;
        *request.mutable_cloud()->mutable_xyz() = PackXyz(capture.points_Sensor);
        request.mutable_cloud()->set_unit(ToProto(capture.unit));
        *request.mutable_cell() = ToCellDescription(cell_, capture.X_BinSensor);
        request.mutable_options()->set_profile(params_.profile);
        request.mutable_options()->set_seed(params_.seed + scan);
        request.mutable_options()->set_disable_simulation(params_.disable_simulation);
        request.mutable_options()->set_max_plans(params_.max_plans);
        const Clock::time_point plan_start = Clock::now();
        const v1::PlanPickResponse response =
            CallPlanner(state_, [&] { return planner_.PlanPick(request, params_.plan_deadline); });
        const double planning_wall_s = SecondsSince(plan_start);
        spdlog::info("cell: round {} scan {}: {} tubes modeled, {} plans{}{} ({:.2f} s)", round, scan,
                     response.tubes_size(), response.plans_size(),
                     response.used_simulation() ? ", simulated" : "",
                     response.bin_empty() ? ", BIN EMPTY" : "", planning_wall_s);
        if (response.bin_empty()) {
          result.reason = CellStopReason::kBinEmpty;
          result.message = fmt::format("bin empty: {} tubes picked in {} attempts ({} scans)", result.picks,
                                       result.attempts, result.scans);
          break;
        }

        const auto base_record = [&](std::uint32_t plan_rank) {
          return nlohmann::json{{"type", "attempt"},
                                {"round", round},
                                {"attempt", result.attempts},
                                {"scan", scan},
                                {"plan_rank", plan_rank},
                                {"seed", params_.seed + scan},
                                {"tubes_left_plan", response.tubes_size()},
                                {"plans", response.plans_size()},
                                {"bin_empty", response.bin_empty()},
                                {"used_simulation", response.used_simulation()},
                                {"truth_before", plan_rank == 0 ? truth_before : Truth()}};
        };
        std::uint32_t executed = 0;
        nlohmann::json skipped = nlohmann::json::array();
        for (int rank = 0; rank < response.plans_size() && executed < params_.max_plans_per_scan; ++rank) {
          if (executed > 0 && limit_reached()) break;
          if (const auto problem = ClearanceProblem(response.plans(rank), rank)) {
            spdlog::debug("cell: plan {} (tube {}) skipped: {}", rank, response.plans(rank).tube_id(),
                          *problem);
            skipped.push_back(
                {{"rank", rank}, {"tube", response.plans(rank).tube_id()}, {"reason", *problem}});
            continue;
          }
          ++executed;
          active.emplace();
          ++result.attempts;
          ++attempts_since_pick;
          active->record = base_record(static_cast<std::uint32_t>(rank));
          active->record["skipped_plans"] = std::move(skipped);
          skipped = nlohmann::json::array();
          if (executed == 1) {
            active->started = scan_start;
            active->device_started = scan_device_start;
          } else {
            active->device_started = DeviceNow();
          }
          active->record["durations"] = {
              {"planning_wall_s", executed == 1 ? planning_wall_s : 0.0},
              {"planning_server_s", executed == 1 ? response.total_seconds() : 0.0}};
          ExecutePlan(response, rank, *active);

          const AttemptResult outcome = *active->result;
          nlohmann::json& rec = active->record;
          rec["result"] = ResultName(static_cast<int>(outcome));
          nlohmann::json& d = rec["durations"];
          d["analysis_wall_s"] = active->analysis_wall_s;
          d["robot_wall_s"] = active->robot_wall_s;
          d["robot_device_s"] = active->robot_device_s;
          d["attempt_wall_s"] = SecondsSince(active->started);
          d["attempt_device_s"] = DeviceNow() - active->device_started;
          rec["truth_after"] = Truth();
          if (sink_) sink_->Write(rec);
          spdlog::info("cell: round {} attempt {}: tube {} {} -> {}", round, result.attempts,
                       rec.value("tube", 0u), rec.value("trajectory_kind", ""),
                       rec["result"].get<std::string>());
          active.reset();
          if (outcome == AttemptResult::kPicked) {
            ++result.picks;
            attempts_since_pick = 0;
            consecutive_failures = 0;
            nudges_since_pick = 0;
            break;
          }
          ++consecutive_failures;
          if (outcome != AttemptResult::kGraspFailed) break;  // the bin changed: rescan
        }
        if (executed == 0) {
          // No plan, or none the tool can execute: nudge a tube off a wall, if one lies along it,
          // then rescan (with the next seed).
          ++consecutive_failures;
          std::optional<NudgePlan> nudge;
          if (params_.nudge.enabled && params_.check_tool_clearance &&
              result.nudges < params_.nudge.max_nudges_per_bin && response.tubes_size() > 0)
            nudge = PlanNudge(response.tubes(), cell_, params_.tool, params_.nudge, params_.approach_height,
                              nudges_since_pick);
          nlohmann::json rec = base_record(0);
          rec["attempt"] = nullptr;
          rec["result"] = "no_plan";
          rec["skipped_plans"] = std::move(skipped);
          rec["durations"] = {{"planning_wall_s", planning_wall_s},
                              {"planning_server_s", response.total_seconds()}};
          if (nudge) {
            ++result.nudges;
            ++nudges_since_pick;
            rec["nudge"] = {{"tube", nudge->tube_id},
                            {"contact", Vec(nudge->p_Bin_contact)},
                            {"wall_distance", nudge->wall_distance},
                            {"direction", Vec(nudge->direction)},
                            {"shift", nudge->shift},
                            {"distance", nudge->distance},
                            {"tcp_pose", PoseJson(nudge->X_BinTcp_press)}};
            active.emplace();
            active->record = std::move(rec);
            active->started = scan_start;
            active->device_started = scan_device_start;
            spdlog::info(
                "cell: round {} scan {}: no executable plan; nudging tube {} ({:.3f} m from a wall) "
                "{:.3f} m along ({:.2f}, {:.2f})",
                round, scan, nudge->tube_id, nudge->wall_distance, nudge->distance, nudge->direction.x(),
                nudge->direction.y());
            ExecuteNudge(*nudge, *active);
            rec = std::move(active->record);
            rec["result"] = "nudge";
            rec["durations"]["robot_wall_s"] = active->robot_wall_s;
            rec["durations"]["robot_device_s"] = active->robot_device_s;
            active.reset();
          }
          rec["durations"]["attempt_wall_s"] = SecondsSince(scan_start);
          rec["durations"]["attempt_device_s"] = DeviceNow() - scan_device_start;
          rec["truth_after"] = Truth();
          if (sink_) sink_->Write(rec);
          if (!nudge)
            spdlog::info("cell: round {} scan {}: no executable plan ({} plans, {} skipped)", round, scan,
                         response.plans_size(), rec["skipped_plans"].size());
        }
      }
    } catch (const CellFault&) {
      throw;
    } catch (const std::exception& e) {
      throw CellFault("controller", FaultKind::kInternal, ToString(state_), e.what());
    }
  } catch (const CellFault& fault) {
    if (active) {
      nlohmann::json& rec = active->record;
      rec["result"] = "fault";
      rec["fault"] = {{"device", fault.device()},
                      {"kind", ToString(fault.kind())},
                      {"state", fault.state()},
                      {"error", fault.error()}};
      rec["durations"]["robot_wall_s"] = active->robot_wall_s;
      rec["durations"]["robot_device_s"] = active->robot_device_s;
      rec["truth_after"] = Truth();
      if (sink_) sink_->Write(rec);
    }
    SafeStop(fault, result);
  }

  if (sink_)
    sink_->Write({{"type", "end"},
                  {"round", round},
                  {"reason", ToString(result.reason)},
                  {"message", result.message},
                  {"picks", result.picks},
                  {"attempts", result.attempts},
                  {"scans", result.scans},
                  {"nudges", result.nudges},
                  {"truth_start", truth_start},
                  {"truth", Truth()}});
  return result;
}

}  // namespace tubepick::cell
