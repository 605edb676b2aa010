// The cell controller's run: start, then scan → plan → picking attempts (cell_attempt.cc) or a
// nudge, until the bin is empty, a limit is reached or a fault ends in a safe stop.

#include "clients/cell/cell_controller.h"

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <utility>

#include "clients/cell/attempt_record.h"
#include "clients/cell/cell_controller_internal.h"
#include "core/common/errors.h"
#include "wire/packed_cloud.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

// "1 tube", "2 tubes".
std::string Count(std::uint32_t n, const char* noun) {
  return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s");
}

const char* ResultName(int result) {
  static const char* const kNames[] = {"picked", "multiple_returned", "none", "grasp_failed", "lost"};
  return kNames[result];
}

/// What the attempts since the last pick came to, the most recent eight at most; a run of the same
/// outcome is one entry, "N × outcome".
std::string AttemptsSincePick(const std::vector<std::string>& since_pick) {
  constexpr std::size_t kShown = 8;
  std::vector<std::string> runs;
  std::vector<std::size_t> run_begin;  // index into since_pick of each run's first outcome
  for (std::size_t i = 0; i < since_pick.size();) {
    std::size_t j = i + 1;
    while (j < since_pick.size() && since_pick[j] == since_pick[i]) ++j;
    runs.push_back(j - i == 1 ? since_pick[i] : fmt::format("{} × {}", j - i, since_pick[i]));
    run_begin.push_back(i);
    i = j;
  }
  const std::size_t n = runs.size();
  if (n <= kShown) return fmt::format("{}", fmt::join(runs, ", "));
  // "N earlier": the attempts and scans before the runs shown.
  return fmt::format("{} earlier, then {}", run_begin[n - kShown],
                     fmt::join(runs.end() - kShown, runs.end(), ", "));
}

}  // namespace

using detail::CallDevice;
using detail::CallPlanner;
using detail::CellMismatchMessage;
using detail::Clock;
using detail::SecondsSince;

std::string detail::CellMismatchMessage(std::uint32_t plans, const std::string& first_reason) {
  return fmt::format(
      "all {} plans of this scan lie outside this controller's cell, none was executed: is the planner "
      "configured with another cell (bin size, sensor pose, place frame) or unit? The first: {}",
      plans, first_reason);
}

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

std::string ToString(Held held) {
  switch (held) {
    case Held::kNothing:
      return "nothing";
    case Held::kTube:
      return "tube";
    case Held::kUnknown:
      return "unknown";
  }
  return "unknown";
}

std::string DescribePlannerWarnings(const CellRunResult& result) {
  if (result.planner_warnings.empty()) return "";
  std::string text;
  for (const auto& [code, scans] : result.planner_warnings)
    text += fmt::format("{}{} in {} of {} scans", text.empty() ? "" : ", ", code, scans, result.scans);
  return "; the planner warned: " + text + " (check the cell)";
}

std::string DescribeTubeMassDoubt(const CellRunResult& result) {
  if (result.tube_mass_doubts == 0) return "";
  return fmt::format("; the lifts doubt tube.mass after {} of {} attempts: {}", result.tube_mass_doubts,
                     result.attempts, result.tube_mass_doubt);
}

std::string DescribeVanishedOverWalls(const CellRunResult& result) {
  const std::size_t n = result.vanished_over_walls.size();
  if (n == 0) return "";
  // The bin found empty with every one of its tubes_per_bin tubes placed: none of them is on the floor
  // (a tree leaning on a wall slides back in when what it leaned on is picked, and is picked later).
  if (result.tubes_expected > 0 && result.picks == result.tubes_expected)
    return fmt::format(
        "; {} hanging over a wall {} not seen there again, but every tube of the bin was placed ({} of "
        "tubes_per_bin {}), so {} not fall out: {}",
        Count(static_cast<std::uint32_t>(n), "tube"), n == 1 ? "was" : "were", result.picks,
        result.tubes_expected, n == 1 ? "it did" : "they did", fmt::join(result.vanished_over_walls, "; "));
  return fmt::format("; {} hanging over a wall {} not seen again, {} have fallen out of the bin: {}",
                     Count(static_cast<std::uint32_t>(n), "tube"), n == 1 ? "was" : "were",
                     n == 1 ? "it may" : "they may", fmt::join(result.vanished_over_walls, "; "));
}

std::string DescribeTubeCount(const CellRunResult& result) {
  if (result.tubes_expected == 0) return "";
  if (result.tubes_unaccounted > 0)
    return fmt::format(
        "; {} of the bin's {} tubes unaccounted for (tubes_per_bin): not placed and not seen in the bin, {} "
        "have fallen out of it or been carried out with another (check the floor around the bin)",
        result.tubes_unaccounted, result.tubes_expected,
        result.tubes_unaccounted == 1 ? "it may" : "they may");
  if (result.picks > result.tubes_expected)
    return fmt::format("; {} tubes placed from a bin of {} (tubes_per_bin): the count is wrong", result.picks,
                       result.tubes_expected);
  return "";
}

std::string DescribeRoundWarnings(const CellRunResult& result) {
  return DescribePlannerWarnings(result) + DescribeTubeMassDoubt(result) + DescribeVanishedOverWalls(result) +
         DescribeTubeCount(result);
}

std::string ToString(CellStopReason reason) {
  switch (reason) {
    case CellStopReason::kBinEmpty:
      return "bin_empty";
    case CellStopReason::kLimitReached:
      return "limit_reached";
    case CellStopReason::kFault:
      return "fault";
    case CellStopReason::kStopped:
      return "stopped";
    case CellStopReason::kDryRun:
      return "dry_run";
  }
  return "fault";
}

std::string ToString(MotionKind kind) {
  switch (kind) {
    case MotionKind::kTransit:
      return "transit";
    case MotionKind::kMoveTo:
      return "move_to";
    case MotionKind::kMoveThrough:
      return "move_through";
    case MotionKind::kGripperMoveTo:
      return "gripper_move_to";
    case MotionKind::kGripperClose:
      return "gripper_close";
    case MotionKind::kGripperOpen:
      return "gripper_open";
  }
  return "unknown";
}

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
  if (observer_) observer_(state);
  CheckStop();
}

void CellController::RequestStop(std::string why) {
  {
    std::lock_guard<std::mutex> lock(stop_mutex_);
    if (stop_requested_.load(std::memory_order_relaxed)) return;  // the first reason stays
    stop_why_ = why.empty() ? "operator stop" : std::move(why);
  }
  stop_requested_.store(true, std::memory_order_release);
  planner_.CancelCalls();  // a PlanPick may run for minutes: the stop does not wait for it
}

void CellController::CheckStop() {
  if (stopping_ || !stop_requested_.load(std::memory_order_acquire)) return;
  stopping_ = true;
  std::string why;
  {
    std::lock_guard<std::mutex> lock(stop_mutex_);
    why = stop_why_;
  }
  spdlog::warn("cell: {} during {}", why, ToString(state_));
  throw StopRequested{why, ToString(state_)};
}

double CellController::DeviceNow() const { return device_clock_ ? device_clock_() : 0.0; }

nlohmann::json CellController::Truth() const { return annotator_ ? annotator_() : nlohmann::json(); }

// ---------------------------------------------------------------- run

CellRunResult CellController::Run(std::uint32_t round) {
  round_ = round;
  stopping_ = false;
  commanded_ = false;
  dry_run_ = false;
  held_ = Held::kUnknown;
  caught_reference_.reset();
  RunState run;
  const nlohmann::json truth_start = Truth();
  const std::optional<StopCause> cause = Guarded([&] {
    StartCell();
    while (ScanAndPick(run)) {
    }
  });
  if (cause) {
    RecordInterruptedAttempt(run, *cause);
    SafeStop(*cause, run.result);
  }
  if (sink_) sink_->Write(EndRecord(round, run.result, truth_start, Truth()));
  return run.result;
}

/// Servo on, activate and open the gripper, go home, zero the F/T sensor there.
void CellController::StartCell() {
  Enter(CellState::kStart);
  commanded_ = true;
  CallDevice("robot", state_, [&] { devices_.robot->ServoOn(params_.robot_timeout); });
  CallDevice("gripper", state_, [&] { devices_.gripper->Activate(params_.gripper_timeout); });
  OpenGripper();
  GoHome(nullptr);
  Enter(CellState::kBias);
  CallDevice("ft_sensor", state_, [&] { devices_.ft_sensor->Bias(params_.ft_timeout); });
}

std::optional<std::string> CellController::LimitReached(const RunState& run) const {
  if (run.attempts_since_pick >= params_.max_attempts_per_tube)
    return fmt::format("{} attempts since the last pick (max_attempts_per_tube = {}: {})",
                       run.attempts_since_pick, params_.max_attempts_per_tube,
                       AttemptsSincePick(run.since_pick));
  if (run.result.attempts >= params_.max_attempts_per_bin)
    return fmt::format("{} attempts in this bin (max_attempts_per_bin = {})", run.result.attempts,
                       params_.max_attempts_per_bin);
  if (run.consecutive_failures >= params_.max_consecutive_failures)
    return fmt::format(
        "{} consecutive failures (max_consecutive_failures = {}{}{})", run.consecutive_failures,
        params_.max_consecutive_failures,
        run.since_pick.empty() ? "" : "; since the last pick: ", AttemptsSincePick(run.since_pick));
  return std::nullopt;
}

bool CellController::ScanAndPick(RunState& run) {
  CellRunResult& result = run.result;
  if (const auto why = LimitReached(run)) {
    result.reason = CellStopReason::kLimitReached;
    result.message = fmt::format("attempt limit reached: {}; {} picked", *why, Count(result.picks, "tube"));
    return false;
  }
  PlannedScan scan = ScanBin(run);
  if (scan.response.bin_empty()) {
    result.reason = CellStopReason::kBinEmpty;
    result.message = fmt::format("bin empty: {} picked in {} ({})", Count(result.picks, "tube"),
                                 Count(result.attempts, "attempt"), Count(result.scans, "scan"));
    CountTubes(result);
    return false;
  }
  if (TryPlans(scan, run) == 0) NoExecutablePlan(scan, run);
  return true;
}

void CellController::CountTubes(CellRunResult& result) const {
  if (params_.tubes_per_bin == 0) return;
  result.tubes_expected = params_.tubes_per_bin;
  result.tubes_unaccounted = result.picks < result.tubes_expected ? result.tubes_expected - result.picks : 0;
  // The round line's words ("; 2 of the bin's 20 tubes ...", or "" when the count is met).
  const std::string said = DescribeTubeCount(result);
  if (!said.empty()) spdlog::warn("cell: round {}: bin empty: {}", round_, said.substr(2));
  if (!result.vanished_over_walls.empty() && result.picks == result.tubes_expected)
    spdlog::info("cell: round {}: bin empty: {}", round_, DescribeVanishedOverWalls(result).substr(2));
}

// ---------------------------------------------------------------- scan, plan

CellController::PlannedScan CellController::ScanBin(RunState& run) {
  Enter(CellState::kScan);
  PlannedScan scan;
  scan.truth_before = Truth();
  scan.started = Clock::now();
  scan.device_started = DeviceNow();
  const devices::Capture capture = Scan();
  scan.index = run.result.scans++;
  PlanPick(capture, scan);
  for (const v1::ModelingWarning& w : scan.response.modeling().warnings())
    ++run.result.planner_warnings[w.code()];
  WatchWalls(scan, capture, run);
  return scan;
}

void CellController::WatchWalls(PlannedScan& scan, const devices::Capture& capture, RunState& run) {
  // After a lift of several tubes, which ones came along is not known (the rotation frees them
  // over the bin's middle): nothing is said for that scan.
  const std::vector<TubeOverWall> gone =
      run.lifted_several
          ? std::vector<TubeOverWall>{}
          : VanishedOverWalls(run.over_walls, capture, cell_.bin, run.touched, params_.wall_watch);
  for (const TubeOverWall& tube : gone) {
    const std::string what = Describe(tube);
    spdlog::warn(
        "cell: round {} scan {}: a tube hung {} though no attempt took it: it may have fallen out of the "
        "bin (check the floor beside that wall)",
        round_, scan.index, what);
    run.result.vanished_over_walls.push_back(what);
    scan.vanished_over_walls.push_back(what);
  }
  run.over_walls = TubesOverWalls(scan.response, cell_.bin, scan.index, params_.wall_watch);
  run.touched.clear();
  run.lifted_several = false;
}

void CellController::TakeVanishedOverWalls(PlannedScan& scan, nlohmann::json& record) {
  if (scan.vanished_over_walls.empty()) return;
  record["vanished_over_walls"] = std::exchange(scan.vanished_over_walls, {});
}

void CellController::PlanPick(const devices::Capture& capture, PlannedScan& scan) {
  Enter(CellState::kPlan);
  v1::PlanPickRequest request;
  *request.mutable_cloud()->mutable_xyz() = PackXyz(capture.points_Sensor);
  request.mutable_cloud()->set_unit(ToProto(capture.unit));
  *request.mutable_cell() = ToCellDescription(cell_, capture.X_BinSensor);
  request.mutable_options()->set_profile(params_.profile);
  request.mutable_options()->set_seed(params_.seed + scan.index);
  request.mutable_options()->set_disable_simulation(params_.disable_simulation);
  request.mutable_options()->set_max_plans(params_.max_plans);
  const Clock::time_point start = Clock::now();
  scan.response = CallPlanner(state_, [&] { return planner_.PlanPick(request, params_.plan_deadline); });
  scan.planning_wall_s = SecondsSince(start);
  const v1::PlanPickResponse& response = scan.response;
  spdlog::info("cell: round {} scan {}: {} tubes modeled, {} plans{}{} ({:.2f} s)", round_, scan.index,
               response.tubes_size(), response.plans_size(), response.used_simulation() ? ", simulated" : "",
               response.bin_empty() ? ", BIN EMPTY" : "", scan.planning_wall_s);
  // The planner's doubts about this cell's inputs: loud the first time, then in the records only.
  for (const v1::ModelingWarning& w : response.modeling().warnings()) {
    const bool first = planner_warnings_seen_.insert(w.code()).second;
    spdlog::log(first ? spdlog::level::warn : spdlog::level::debug, "cell: the planner warns ({}): {}{}",
                w.code(), w.message(),
                first ? " (said once; every attempt record lists it as planner_warnings)" : "");
  }
}

// ---------------------------------------------------------------- attempts

std::uint32_t CellController::TryPlans(PlannedScan& scan, RunState& run) {
  std::uint32_t executed = 0;
  for (int rank = 0; rank < scan.response.plans_size() && executed < params_.max_plans_per_scan; ++rank) {
    if (executed > 0 && LimitReached(run)) break;
    const v1::PickPlan& plan = scan.response.plans(rank);
    std::optional<PlanSkip> skip = RepeatsFailedGrasp(plan, run);
    if (!skip) skip = ExecutionProblem(scan.response, rank);
    if (skip) {
      spdlog::debug("cell: plan {} (tube {}) skipped: {}", rank, plan.tube_id(), skip->reason);
      scan.skipped.push_back(SkippedPlanJson(rank, plan.tube_id(), skip->check, skip->reason));
      if (skip->check == "cell_frame" && scan.cell_mismatches++ == 0) scan.first_cell_mismatch = skip->reason;
      continue;
    }
    ++executed;
    const AttemptResult outcome = PickAttempt(scan, rank, executed == 1, run);
    if (!CountAttempt(outcome, run)) break;
  }
  return executed;
}

CellController::AttemptResult CellController::PickAttempt(PlannedScan& scan, int rank, bool first_of_scan,
                                                          RunState& run) {
  Attempt& attempt = BeginAttempt(scan, rank, first_of_scan, run);
  ExecutePlan(scan.response.plans(rank), rank, attempt);
  return FinishAttempt(run);
}

/// The attempt's record so far; the scan's time counts towards its first attempt.
CellController::Attempt& CellController::BeginAttempt(PlannedScan& scan, int rank, bool first_of_scan,
                                                      RunState& run) {
  Attempt& attempt = run.active.emplace();
  ++run.result.attempts;
  ++run.attempts_since_pick;
  attempt.record = BaseRecord(scan, rank, run.result.attempts);
  attempt.record["skipped_plans"] = std::exchange(scan.skipped, nlohmann::json::array());
  TakeVanishedOverWalls(scan, attempt.record);
  if (first_of_scan) {
    attempt.started = scan.started;
    attempt.device_started = scan.device_started;
  } else {
    attempt.device_started = DeviceNow();
  }
  attempt.record["durations"] = PlanningDurationsJson(first_of_scan ? scan.planning_wall_s : 0.0,
                                                      first_of_scan ? scan.response.total_seconds() : 0.0);
  return attempt;
}

/// Records the attempt's result and durations, writes the record.
CellController::AttemptResult CellController::FinishAttempt(RunState& run) {
  Attempt& attempt = *run.active;
  const AttemptResult outcome = *attempt.result;
  nlohmann::json& record = attempt.record;
  record["result"] = ResultName(static_cast<int>(outcome));
  nlohmann::json& d = record["durations"];
  d["analysis_wall_s"] = attempt.analysis_wall_s;
  d["robot_wall_s"] = attempt.robot_wall_s;
  d["robot_device_s"] = attempt.robot_device_s;
  d["attempt_wall_s"] = SecondsSince(attempt.started);
  d["attempt_device_s"] = DeviceNow() - attempt.device_started;
  record["truth_after"] = Truth();
  if (const auto a = record.find("analysis"); a != record.end() && a->value("outcome", "") == "multiple")
    run.lifted_several = true;
  // A grasp that closed on nothing took nothing: should its tube be gone from over a wall at the
  // next scan, nothing the cell holds explains it.
  if (outcome != AttemptResult::kGraspFailed) run.touched.push_back(record.value("tube", 0u));
  CountAttemptWrench(attempt, run.result);
  run.since_pick.push_back(DescribeAttemptBriefly(record));
  RememberFailedGrasp(outcome, attempt, run);
  if (sink_) sink_->Write(record);
  spdlog::info("cell: round {} attempt {}: tube {} {} -> {}", round_, run.result.attempts,
               record.value("tube", 0u), record.value("trajectory_kind", ""),
               record["result"].get<std::string>());
  run.active.reset();
  return outcome;
}

void CellController::CountAttemptWrench(const Attempt& attempt, CellRunResult& result) {
  result.local_analyses += attempt.local_analyses;
  if (const auto doubt = attempt.record.find("tube_mass_doubt"); doubt != attempt.record.end()) {
    ++result.tube_mass_doubts;
    result.tube_mass_doubt = doubt->at("message").get<std::string>();
  }
}

/// A grasp that closed on nothing or lifted nothing leaves the bin as it was: remember where. Any
/// other attempt moved tubes (picked, put back, lost): the grasps that failed before may work now.
void CellController::RememberFailedGrasp(AttemptResult outcome, const Attempt& attempt, RunState& run) {
  if (outcome != AttemptResult::kNone && outcome != AttemptResult::kGraspFailed) {
    run.failed_grasps.clear();
    run.nudges_done.clear();
    return;
  }
  if (!attempt.p_Bin_grasp) return;
  run.failed_grasps.push_back(
      {*attempt.p_Bin_grasp, run.result.attempts, ResultName(static_cast<int>(outcome))});
}

/// The plan grasps within failed_grasp_radius of a grasp that failed since the last pick.
std::optional<CellController::PlanSkip> CellController::RepeatsFailedGrasp(const v1::PickPlan& plan,
                                                                           const RunState& run) const {
  if (params_.failed_grasp_radius <= 0.0) return std::nullopt;
  const Eigen::Vector3d p_Bin_grasp = FromProto(plan.grasp().tcp_pose().position());
  for (const RunState::FailedGrasp& failed : run.failed_grasps) {
    const double distance = (p_Bin_grasp - failed.p_Bin_grasp).norm();
    if (distance <= params_.failed_grasp_radius)
      return PlanSkip{
          "failed_grasp",
          fmt::format("{:.3f} m from the grasp of attempt {} ({}) at ({:.3f}, {:.3f}, {:.3f}) m "
                      "(failed_grasp_radius {:.3f} m): the bin is as it was then",
                      distance, failed.attempt, failed.result, failed.p_Bin_grasp.x(), failed.p_Bin_grasp.y(),
                      failed.p_Bin_grasp.z(), params_.failed_grasp_radius)};
  }
  return std::nullopt;
}

bool CellController::CountAttempt(AttemptResult outcome, RunState& run) {
  if (outcome == AttemptResult::kLost) ++run.result.lost;
  if (outcome == AttemptResult::kPicked) {
    ++run.result.picks;
    run.attempts_since_pick = 0;
    run.since_pick.clear();
    run.consecutive_failures = 0;
    run.nudges_since_pick = 0;
    return false;
  }
  ++run.consecutive_failures;
  return outcome == AttemptResult::kGraspFailed;  // otherwise the bin changed: rescan
}

nlohmann::json CellController::BaseRecord(const PlannedScan& scan, int rank, std::uint32_t attempt) {
  AttemptRecordHead head;
  head.round = round_;
  head.attempt = attempt;
  head.scan = scan.index;
  head.plan_rank = static_cast<std::uint32_t>(rank);
  head.seed = params_.seed + scan.index;
  head.truth_before = rank == 0 ? scan.truth_before : Truth();
  return AttemptRecord(head, scan.response);
}

// ---------------------------------------------------------------- no plan, nudge

/// No plan, or none the tool can execute: nudge a tube off a wall, if one lies along it, then
/// rescan (with the next seed).
void CellController::NoExecutablePlan(PlannedScan& scan, RunState& run) {
  ++run.consecutive_failures;
  // Every plan lies outside this controller's cell: the planner's tubes are in another frame, so
  // no nudge either (it would press where the planner, not the bin, has a tube).
  const bool cell_mismatch = scan.response.plans_size() > 0 &&
                             scan.cell_mismatches == static_cast<std::uint32_t>(scan.response.plans_size());
  std::optional<NudgePlan> nudge = cell_mismatch ? std::nullopt : PlanNudgeIfAllowed(scan.response, run);
  nlohmann::json record = BaseRecord(scan, 0, run.result.attempts);
  if (nudge) {
    if (std::optional<std::string> repeat = RepeatsNudge(*nudge, run)) {
      spdlog::warn("cell: round {} scan {}: {}", round_, scan.index, *repeat);
      record["nudge_not_repeated"] = {{"nudge", NudgeJson(*nudge)}, {"reason", *repeat}};
      nudge.reset();
    }
  }
  TakeVanishedOverWalls(scan, record);
  record["attempt"] = nullptr;
  record["result"] = "no_plan";
  record["skipped_plans"] = std::exchange(scan.skipped, nlohmann::json::array());
  if (cell_mismatch) {
    const std::string message = CellMismatchMessage(scan.cell_mismatches, scan.first_cell_mismatch);
    record["cell_mismatch"] = message;
    spdlog::error("cell: round {} scan {}: {}", round_, scan.index, message);
  }
  record["durations"] = PlanningDurationsJson(scan.planning_wall_s, scan.response.total_seconds());
  if (nudge) {
    record = Nudge(*nudge, std::move(record), scan, run);
    run.failed_grasps.clear();  // the nudge moved a tube
  }
  record["durations"]["attempt_wall_s"] = SecondsSince(scan.started);
  record["durations"]["attempt_device_s"] = DeviceNow() - scan.device_started;
  record["truth_after"] = Truth();
  run.since_pick.push_back(DescribeAttemptBriefly(record));
  if (sink_) sink_->Write(record);
  if (!nudge)
    spdlog::info("cell: round {} scan {}: no executable plan ({} plans, {} skipped)", round_, scan.index,
                 scan.response.plans_size(), record["skipped_plans"].size());
}

/// The nudge presses where one since tubes last moved otherwise pressed, and the tube there lies as
/// far from the wall: that one moved nothing (nudge.repeat_radius).
std::optional<std::string> CellController::RepeatsNudge(const NudgePlan& nudge, const RunState& run) const {
  const double radius = params_.nudge.repeat_radius;
  if (radius <= 0.0) return std::nullopt;
  for (const RunState::NudgeDone& done : run.nudges_done) {
    const double distance = (nudge.p_Bin_contact - done.p_Bin_contact).norm();
    if (distance > radius || std::abs(nudge.wall_distance - done.wall_distance) > radius) continue;
    const Eigen::Vector3d& p = nudge.p_Bin_contact;
    const double above_walls = p.z() - cell_.bin.inner_size.z();
    return fmt::format(
        "tube {} not nudged again: "
        "its contact at ({:.3f}, {:.3f}, {:.3f}) m, {:.3f} m from a wall, "
        "is {:.3f} m from the nudge of scan {}, which did not move it "
        "(nudge.repeat_radius {:.3f} m){}; "
        "clear it by hand if no plan comes",
        nudge.tube_id, p.x(), p.y(), p.z(), nudge.wall_distance, distance, done.scan, radius,
        above_walls > 0.0
            ? fmt::format(": {:.3f} m above the wall top, it may hang over the wall", above_walls)
            : ": it may be caught or wedged");
  }
  return std::nullopt;
}

std::optional<NudgePlan> CellController::PlanNudgeIfAllowed(const v1::PlanPickResponse& response,
                                                            const RunState& run) const {
  if (!params_.nudge.enabled || !params_.check_tool_clearance ||
      run.result.nudges >= params_.nudge.max_nudges_per_bin || response.tubes_size() == 0)
    return std::nullopt;
  return PlanNudge(response.tubes(), cell_, params_.tool, params_.nudge, params_.approach_height,
                   TransitHeight(params_, cell_), run.nudges_since_pick);
}

/// The nudge (kNudge) as the scan's attempt: `record` gets its plan, result and robot durations.
nlohmann::json CellController::Nudge(const NudgePlan& nudge, nlohmann::json record, const PlannedScan& scan,
                                     RunState& run) {
  ++run.result.nudges;
  ++run.nudges_since_pick;
  run.nudges_done.push_back({nudge.p_Bin_contact, nudge.wall_distance, scan.index});
  run.touched.push_back(nudge.tube_id);
  record["nudge"] = NudgeJson(nudge);
  Attempt& attempt = run.active.emplace();
  attempt.record = std::move(record);
  attempt.started = scan.started;
  attempt.device_started = scan.device_started;
  spdlog::info(
      "cell: round {} scan {}: no executable plan; nudging tube {} ({:.3f} m from a wall) "
      "{:.3f} m along ({:.2f}, {:.2f})",
      round_, scan.index, nudge.tube_id, nudge.wall_distance, nudge.distance, nudge.direction.x(),
      nudge.direction.y());
  ExecuteNudge(nudge, attempt);
  record = std::move(attempt.record);
  record["result"] = "nudge";
  record["durations"]["robot_wall_s"] = attempt.robot_wall_s;
  record["durations"]["robot_device_s"] = attempt.robot_device_s;
  run.active.reset();
  return record;
}

// ---------------------------------------------------------------- fault (the safe stop: cell_safe_stop.cc)

void CellController::RecordInterruptedAttempt(RunState& run, const StopCause& cause) {
  if (!run.active) return;
  CountAttemptWrench(*run.active, run.result);
  nlohmann::json& record = run.active->record;
  // A tube already placed when the fault (or the stop) came, on the way home, is a pick, with the
  // fault beside it.
  const bool placed = record.value("placed", false);
  if (placed) ++run.result.picks;
  if (cause.fault) {
    record["result"] = placed ? "picked" : "fault";
    record["fault"] = FaultJson(*cause.fault);
  } else {
    record["result"] = placed ? "picked" : "stopped";
    record["stop"] = OperatorStopJson(cause.state, cause.why);
  }
  record["durations"]["robot_wall_s"] = run.active->robot_wall_s;
  record["durations"]["robot_device_s"] = run.active->robot_device_s;
  record["truth_after"] = Truth();
  if (sink_) sink_->Write(record);
  run.active.reset();
}

}  // namespace tubepick::cell
