#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "clients/cell/cell_controller_params.h"
#include "clients/cell/cell_fault.h"
#include "clients/cell/cell_records.h"
#include "clients/cell/nudge.h"
#include "clients/cell/planner_client.h"
#include "core/common/cell_config.h"
#include "devices/force_torque_sensor.h"
#include "devices/gripper.h"
#include "devices/robot.h"
#include "devices/scanner.h"

namespace tubepick::cell {

/// The states of the pick-and-place cycle (thesis Figure 5.1 with the skills of Table 5.1).
enum class CellState {
  kStart,        ///< servo on, activate and open the gripper, go home
  kBias,         ///< zero the F/T sensor at home (empty gripper)
  kScan,         ///< PhotoneoSkill: capture the bin from home
  kPlan,         ///< TubePickPlannerSkill: PlanPick
  kApproach,     ///< MoveArmSkill: transit to the pre-grasp pose, open to the grasp width
  kReference,    ///< F/T reference with the gripper empty, in the grasp orientation
  kGrasp,        ///< down to the grasp pose, RobotiqGripperSkill: close
  kLift,         ///< MoveArmSkill along the plan's waypoints
  kAnalyze,      ///< ForceTorqueAnalysisSkill: AnalyzeWrench
  kPlace,        ///< transit to the place pose, open
  kResolve,      ///< resolution rotations, each followed by a new reading and analysis
  kReturnToBin,  ///< lower the tubes back into the bin and open
  kNudge,        ///< no executable plan: drag a tube lying along a wall towards the middle
  kRelease,      ///< open after nothing was grasped / lifted
  kHome,         ///< back to the home pose
  kSafeStop,     ///< holding a tube: back over the bin, release there if possible; else stop where it is
};

/// "start", "bias", "scan", ...
std::string ToString(CellState state);

/// The four devices of the cell; not owned, must outlive the controller.
struct CellDevices {
  devices::Scanner* scanner = nullptr;
  devices::Robot* robot = nullptr;
  devices::Gripper* gripper = nullptr;
  devices::ForceTorqueSensor* ft_sensor = nullptr;
};

/// What the gripper holds, as far as the controller knows. kUnknown (a close that did not report,
/// a slip check that failed) is treated as holding.
enum class Held { kNothing, kTube, kUnknown };
/// "nothing", "tube", "unknown".
std::string ToString(Held held);

/// What a safe stop did. Holding a tube, the controller never opens the gripper outside the bin's
/// interior: it moves the tube back over the bin, lowers it to the release height and opens there;
/// when the arm cannot move it keeps the gripper closed and says where the tube is held.
struct SafeStopOutcome {
  /// What the gripper held when the fault stopped the run.
  Held held = Held::kNothing;
  /// "stopped" (nothing held: no motion), "released_in_bin" (moved over the bin and opened),
  /// "kept_closed" (the arm could not move, or the gripper could not open: the tube is still held),
  /// "load_on_tool" (opened over the bin, but what was caught on the tool still hangs there: the
  /// arm stays at the release pose inside the bin).
  std::string action = "stopped";
  /// The TCP where the safe stop ended, bin frame (nullopt: the robot did not report it).
  std::optional<Eigen::Vector3d> p_Bin_tcp;
};

/// How a run ended.
enum class CellStopReason {
  kBinEmpty,      ///< the planner reported an empty bin
  kLimitReached,  ///< an attempt limit (per tube, per bin, consecutive failures)
  kFault,         ///< a device or planner fault; a safe stop was performed
  kStopped,       ///< the operator asked (CellController::RequestStop); a safe stop was performed
  kDryRun,        ///< CellController::DryRun: scanned and planned, nothing moved
};
/// "bin_empty", "limit_reached", "fault", "stopped", "dry_run".
std::string ToString(CellStopReason reason);

struct CellRunResult {
  CellStopReason reason = CellStopReason::kBinEmpty;
  /// One line for the operator: what happened and, for a fault, the device, state and error.
  std::string message;
  std::uint32_t picks = 0;
  /// Picking attempts (grasp executions).
  std::uint32_t attempts = 0;
  std::uint32_t scans = 0;
  /// Nudges (NudgeParams) performed.
  std::uint32_t nudges = 0;
  /// Tubes lost between the grasp and the place pose (slips and drops), each recorded as "lost".
  std::uint32_t lost = 0;
  /// AnalyzeWrench calls answered by the local fallback (the planner unreachable while holding).
  std::uint32_t local_analyses = 0;
  /// Set when reason == kFault.
  std::optional<CellFault> fault;
  /// Set when reason == kStopped: the reason given to RequestStop ("operator stop (SIGINT)").
  std::optional<std::string> operator_stop;
  /// Set when reason == kFault or kStopped: what the safe stop did with what the gripper held.
  std::optional<SafeStopOutcome> safe_stop;
  /// Scans whose planner answer warned about the cell's inputs, per warning code
  /// (ModelingWarning.code, e.g. "tube_length_shorter_than_scan").
  std::map<std::string, std::uint32_t> planner_warnings;
  /// Attempts after whose lift the cell's recent lifts weighed no whole number of tubes against
  /// tube.mass (CheckTubeMass), and the last such doubt ("" when none).
  std::uint32_t tube_mass_doubts = 0;
  std::string tube_mass_doubt;
  /// Tubes seen hanging over a wall that a later scan no longer showed though no attempt took them
  /// (VanishedOverWalls): they may have fallen out of the bin. Describe(TubeOverWall) each.
  std::vector<std::string> vanished_over_walls;
  /// The bin found empty (kBinEmpty) and CellControllerParams::tubes_per_bin known: that count, and
  /// how many of its tubes were not placed (tubes_per_bin − picks; 0 when picks reach it). 0 / 0
  /// otherwise.
  std::uint32_t tubes_expected = 0;
  std::uint32_t tubes_unaccounted = 0;
};

/// "; the planner warned: tube_length_shorter_than_scan in 8 of 8 scans (check the cell)" for the
/// round's line, or "" when no answer of the round warned.
std::string DescribePlannerWarnings(const CellRunResult& result);

/// "; the lifts doubt tube.mass after 4 of 6 attempts: <the last doubt>" for the round's line, or ""
/// when no lift of the round did.
std::string DescribeTubeMassDoubt(const CellRunResult& result);
/// "; 1 tube hanging over a wall was not seen again, it may have fallen out of the bin: over the
/// -y wall at ... m, not seen again after scan 5", or "".
std::string DescribeVanishedOverWalls(const CellRunResult& result);

/// "; 1 of the bin's 20 tubes unaccounted for (tubes_per_bin): ...", "; 21 tubes placed from a bin
/// of 20 (tubes_per_bin): ...", or "" (the count not known, met, or the bin not found empty).
std::string DescribeTubeCount(const CellRunResult& result);

/// All of the above, as the round's line ends.
std::string DescribeRoundWarnings(const CellRunResult& result);

/// What a command of a run does (PlannedMotion).
enum class MotionKind {
  kTransit,        ///< Robot::MoveTo each pose of `via`, then X_BinTcp, at transit speed (up, across, down)
  kMoveTo,         ///< Robot::MoveTo X_BinTcp
  kMoveThrough,    ///< Robot::MoveThrough waypoints_Bin (from the pose before it); X_BinTcp is where it ends
  kGripperMoveTo,  ///< Gripper::MoveTo gripper_opening
  kGripperClose,   ///< Gripper::Close
  kGripperOpen,    ///< Gripper::Open
};
/// "transit", "move_to", "move_through", "gripper_move_to", "gripper_close", "gripper_open".
std::string ToString(MotionKind kind);

/// One command a run would give the robot or the gripper (CellController::DryRun), bin frame.
struct PlannedMotion {
  MotionKind kind = MotionKind::kMoveTo;
  /// The state the run would be in ("approach", "grasp", "lift", "place", "home").
  CellState state = CellState::kApproach;
  /// What it is for, for the operator ("transit to the pre-grasp pose", "open to the grasp width", ...).
  std::string step;
  /// Robot motions: the TCP pose at the end. Gripper commands: where the TCP is meanwhile.
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  /// kTransit: the poses moved to before X_BinTcp (up to transit height, across), in order;
  /// kMoveTo: the stops on the way (the place descent's, where it reads the F/T).
  std::vector<Eigen::Isometry3d> via;
  /// kMoveThrough: the TCP translations from the pose before it, bin axes (the first is (0, 0, 0)).
  std::vector<Eigen::Vector3d> waypoints_Bin;
  /// TCP speed of robot motions, m/s; closing / opening speed of Gripper::MoveTo and Close, m/s
  /// (0 for Gripper::Open: the device's own).
  double speed = 0.0;
  /// kGripperMoveTo: the width the fingers open to, m.
  std::optional<double> gripper_opening;
  /// kGripperMoveTo, kGripperClose: the force, N.
  std::optional<double> gripper_force;
};

/// What CellController::DryRun found: the commands the best executable plan of one scan would
/// give, in order, without any of them given.
struct DryRunResult {
  /// kDryRun (planned; `motions` empty when no plan was executable), kBinEmpty, or kFault /
  /// kStopped (a dry run's safe stop never moves: it only says where the arm is).
  CellRunResult run;
  bool bin_empty = false;
  /// The plan the motions are for: its rank in the planner's answer and its tube.
  std::optional<std::uint32_t> plan_rank;
  std::uint32_t tube = 0;
  /// Plans skipped as a run would skip them: [{"rank", "tube", "check", "reason"}].
  nlohmann::json skipped_plans = nlohmann::json::array();
  /// Set when every plan was skipped because it does not fit this controller's cell.
  std::optional<std::string> cell_mismatch;
  /// The robot's TCP (it was not moved) and the gripper's status, as read at the start.
  std::optional<Eigen::Isometry3d> X_BinTcpStart;
  std::optional<devices::GripperStatus> gripper;
  /// The commands of the plan's attempt as a run would give them from home, for the outcome
  /// "one tube held": approach (transit to the pre-grasp pose, open to the grasp width), grasp
  /// (down, close), lift (the waypoints), place (transit above the place pose, down, open, up),
  /// home. The other outcomes (nothing grasped or lifted, several tubes) are decided at run time.
  std::vector<PlannedMotion> motions;
};

/// The dry run for the operator: how it ended, the plan, and one line per command.
std::string FormatDryRun(const DryRunResult& dry);
/// {"reason", "message", "bin_empty", "plan_rank", "tube", "skipped_plans", "cell_mismatch",
/// "robot_pose", "gripper", "motions": [{"kind", "state", "step", "tcp_pose", "via", "waypoints",
/// "speed", "gripper_opening", "gripper_force"}]}.
nlohmann::json DryRunJson(const DryRunResult& dry);

/// The cell controller: runs the pick-and-place cycle of the thesis (§5.1-5.2) until the bin is
/// empty, a limit is reached or a fault stops it.
///
///   start → bias F/T → [scan → PlanPick → bin empty? end
///     → approach (pre-grasp, open to the grasp width) → F/T reference → grasp → object detected?
///         no: open, count a failed grasp, next plan of the same scan or rescan
///     → lift along the waypoints → object still held? → read F/T → AnalyzeWrench
///         SINGLE: transit to above the place pose (object status after every segment), a reading
///           there must still weigh a tube, down, object status, open, count the pick
///         NONE: open, rescan
///         MULTIPLE: resolution motions in order (back to the lift pose, re-read, re-analyse after
///           each) → single: place; still several: lower into the bin, open, rescan] → ...
///
/// A tube that slips out between the grasp and the place (the gripper stops reporting an object,
/// or the load above the place pose is gone) is recorded as "lost" with where and when, and the
/// round goes on with a rescan: never counted as picked. AnalyzeWrench that cannot reach the planner
/// (UNAVAILABLE after the client's retries) runs the same analysis locally (LocalAnalyzeWrench) and
/// the record says so ("analysis_fallback"). A timed-out F/T reading is read again, readings far
/// from the median are dropped as spikes, a timed-out or empty scan is scanned again.
///
/// Faults end in a safe stop that knows what the gripper holds (Held): with nothing held the arm
/// stops where it is; holding a tube (or not sure: a close that faulted) it goes up, over the
/// bin's middle, down to safe_release_height and opens there; when the arm cannot move or the
/// gripper cannot open it keeps the gripper closed and reports where the tube is held. The gripper
/// is never opened with a tube outside the bin, except on the place pose.
///
/// The F/T reference is taken per attempt at the pre-grasp pose (gripper empty, already in the
/// grasp orientation), which is the thesis' "reference with no object held" without the drift and
/// orientation change between the start of a round and a later pick.
///
/// Plans that do not fit this controller's cell (CellFrameProblem: a grasp, pre-grasp or lift waypoint
/// outside its bin, a place pose away from its place frame: a planner configured with another cell
/// or in millimetres), that the arm cannot reach (Robot::Limits: pre-grasp, grasp, lift waypoints,
/// placement) or the tool cannot execute without touching the bin (ToolClearanceProblem) are
/// skipped before any motion, and so are plans that grasp within failed_grasp_radius of a grasp that
/// closed on or lifted nothing since tubes last moved (the bin is as it was: the same grasp fails the
/// same way); all are listed in the next record's skipped_plans ({rank, tube, check: "failed_grasp" |
/// "cell_frame" | "robot_limits" | "tool_clearance", reason}); when every plan of a scan was skipped
/// as not fitting the cell, its "no_plan" record says so (cell_mismatch) and no nudge is tried; a scan
/// without an executable plan is a "no_plan" record and a rescan — or, when the planner modeled a tube lying
/// along a wall (PlanNudge) and the nudge limit allows, a "nudge": close the gripper, press on the tube's
/// top, drag it away from the wall, open at the top, go home and rescan. A scan that ends in a nudge counts
/// as a consecutive failure (not as a picking attempt); max_nudges_per_bin bounds them per run.
///
/// Every picking attempt (and every scan without a plan) is one record ("type": "attempt"):
///   round, attempt, scan, plan_rank, seed, tubes_left_plan (tubes the planner modeled),
///   plans (count), bin_empty, used_simulation, tube, trajectory_kind, cost, grasp {tcp_pose,
///   opening_width}, gripper (status after closing), wrench {reference, lift, after_resolution[]},
///   analysis {outcome, tube_ratio, held_weight, estimated_count, motions}, resolution {available,
///   used, succeeded}, result ("picked", "multiple_returned", "none", "grasp_failed", "no_plan",
///   "nudge", "lost", "fault"), lost {state, detected_by, detail, device_time_s, p_Bin_tcp} (result
///   "lost"), analysis_fallback {local_analyses, planner_error}, nudge {tube, contact, wall_distance,
///   direction, shift, distance, tcp_pose} (result "nudge"), fault {device, kind, state, error}, durations
///   {planning_wall_s, planning_server_s, analysis_wall_s, robot_wall_s, robot_device_s, attempt_wall_s,
///   attempt_device_s}, truth_before / truth_after (the annotator's object, when set).
/// A safe stop writes {"type": "safe_stop", ...}; every run ends with {"type": "end", reason,
/// message, picks, attempts, scans, nudges, truth}.
///
/// The operator stops a run with RequestStop (from any thread): the run notices it at its next state
/// or robot motion and ends through the same safe stop a fault uses (a held tube is released over
/// the bin), with reason kStopped; the attempt under way is recorded with result "stopped", the
/// safe_stop record has device "operator", kind "stop" and the reason given.
///
/// DryRun scans and plans once without moving anything and returns the commands the best executable
/// plan would give (DryRunResult), with a {"type": "dry_run", ...} record (DryRunJson's fields).
///
/// Poses are named for their frames: X_BinTcp… is a TCP pose in the bin frame (X_BinTcpGrasp,
/// X_BinTcpPreGrasp, X_BinTcpLift, X_BinTcpPlace, X_BinHome), p_Bin_… a position in it. The source
/// is cut by step: cell_controller.cc (the run: start, scan, plan, attempts, nudge, stop requests),
/// cell_dry_run.cc, cell_frame_check.cc (plans against this cell), cell_safe_stop.cc,
/// cell_attempt.cc (one attempt: approach … place / resolve / put back), cell_device_calls.cc (the
/// device and planner calls), attempt_record.cc (the records' parts).
class CellController {
 public:
  /// @throws InvalidArgument when a device pointer is null or params/cell are invalid.
  CellController(CellDevices devices, PlannerClient& planner, CellConfig cell, CellControllerParams params,
                 RecordSink* sink);

  /// Device time in seconds (the simulated cell's clock); robot durations are also measured in it.
  void set_device_clock(std::function<double()> clock) { device_clock_ = std::move(clock); }
  /// Ground truth the controller cannot see (the simulated cell's tube counts), added to each
  /// record as truth_before / truth_after.
  void set_annotator(std::function<nlohmann::json()> annotator) { annotator_ = std::move(annotator); }

  /// Called on every state the controller enters (a fault injector, a monitor); on the run's thread.
  void set_state_observer(std::function<void(CellState)> observer) { observer_ = std::move(observer); }

  /// Runs one bin. Never throws for device or planner failures: they end in a safe stop and a
  /// kFault result.
  CellRunResult Run(std::uint32_t round = 0);

  /// Scans and plans once, moving nothing: no servo on, no robot motion, no gripper command (the
  /// robot's pose and the gripper's status are read); then lists the commands a run would give for
  /// the best plan it would execute (the same skipping rules), in the bin frame. Writes one
  /// {"type": "dry_run"} record. Never throws for device or planner failures (kFault, no motion).
  DryRunResult DryRun(std::uint32_t round = 0);

  /// Asks the run under way (or the next one) to stop: at its next state or robot motion it ends
  /// through the safe stop, with reason kStopped and a message naming `why` (e.g. "operator stop
  /// (SIGINT)"). Thread-safe: may be called from any thread, any number of times (the first reason
  /// stays); not async-signal-safe (a signal handler sets a flag that a thread turns into this
  /// call). A device or planner call under way is not interrupted: the stop comes when it returns
  /// (a PlanPick may take up to plan_deadline). A stop before anything was commanded moves nothing.
  /// The controller stays stopped: a later Run or DryRun stops at its first state.
  void RequestStop(std::string why);
  bool stop_requested() const { return stop_requested_.load(std::memory_order_acquire); }

  /// The state the controller is in (kSafeStop after a fault).
  CellState state() const { return state_; }

 private:
  struct Attempt;      ///< one picking attempt (or nudge) under way: its record and durations
  struct RunState;     ///< one run's counters, result and the attempt under way
  struct PlannedScan;  ///< one scan and the planner's answer to it
  struct PlanPoses;    ///< the TCP poses of one plan, bin frame
  enum class AttemptResult { kPicked, kMultipleReturned, kNone, kGraspFailed, kLost };
  struct TubeLost;       ///< thrown inside an attempt when the held tube is gone
  struct StopRequested;  ///< thrown at a state or a motion after RequestStop
  struct StopCause;      ///< why a run ends in the safe stop: a fault or the operator
  /// Why a plan is skipped: which check ("failed_grasp", "cell_frame", "robot_limits",
  /// "tool_clearance") and why.
  struct PlanSkip {
    std::string check;
    std::string reason;
  };

  // The run (cell_controller.cc): start, then scan → plan → attempts or a nudge, until a stop.
  /// Runs `body`; a fault or a stop request it throws is returned (other exceptions: an internal fault).
  template <typename Body>
  std::optional<StopCause> Guarded(Body&& body);
  void StartCell();
  /// Why no further attempt may be made (an attempt limit), or nullopt.
  std::optional<std::string> LimitReached(const RunState& run) const;
  /// One scan and what follows it; false when the run ends (limit reached, bin empty).
  bool ScanAndPick(RunState& run);
  PlannedScan ScanBin(RunState& run);
  void PlanPick(const devices::Capture& capture, PlannedScan& scan);
  /// Tubes the last scan showed hanging over a wall that this one's cloud does not show, though no
  /// attempt or nudge took them (nor a lift of several tubes): logged, recorded with the next
  /// record and on the round's result.
  void WatchWalls(PlannedScan& scan, const devices::Capture& capture, RunState& run);
  /// The bin found empty: sets result.tubes_expected and tubes_unaccounted from tubes_per_bin (if
  /// known) and warns when the picks fall short of it or pass it.
  void CountTubes(CellRunResult& result) const;
  /// Moves the scan's vanished_over_walls into `record` (the first record of the scan).
  static void TakeVanishedOverWalls(PlannedScan& scan, nlohmann::json& record);
  /// The scan's plans in rank order, skipping those that cannot be executed; returns how many ran.
  std::uint32_t TryPlans(PlannedScan& scan, RunState& run);
  AttemptResult PickAttempt(PlannedScan& scan, int rank, bool first_of_scan, RunState& run);
  Attempt& BeginAttempt(PlannedScan& scan, int rank, bool first_of_scan, RunState& run);
  AttemptResult FinishAttempt(RunState& run);
  /// Adds what the attempt's wrench analyses counted (local analyses, a tube.mass doubt) to `result`.
  static void CountAttemptWrench(const Attempt& attempt, CellRunResult& result);
  /// Counts the attempt's outcome; true when the next plan of the same scan may be tried.
  bool CountAttempt(AttemptResult outcome, RunState& run);
  /// Keeps the grasp of an attempt that closed on or lifted nothing (params.failed_grasp_radius);
  /// forgets them all after an attempt that moved tubes.
  void RememberFailedGrasp(AttemptResult outcome, const Attempt& attempt, RunState& run);
  /// "failed_grasp" when the plan's grasp point is within failed_grasp_radius of such a grasp.
  std::optional<PlanSkip> RepeatsFailedGrasp(const v1::PickPlan& plan, const RunState& run) const;
  /// A scan without an executable plan: a "no_plan" record, or a nudge and its record.
  void NoExecutablePlan(PlannedScan& scan, RunState& run);
  std::optional<NudgePlan> PlanNudgeIfAllowed(const v1::PlanPickResponse& response,
                                              const RunState& run) const;
  /// Why `nudge` would repeat a nudge that moved nothing (nudge.repeat_radius), or nullopt.
  std::optional<std::string> RepeatsNudge(const NudgePlan& nudge, const RunState& run) const;
  nlohmann::json Nudge(const NudgePlan& nudge, nlohmann::json record, const PlannedScan& scan, RunState& run);
  /// The "type": "attempt" record's common fields; truth_before is the scan's for rank 0.
  nlohmann::json BaseRecord(const PlannedScan& scan, int rank, std::uint32_t attempt);
  /// The attempt under way when `cause` stopped the run, recorded as "fault" or "stopped".
  void RecordInterruptedAttempt(RunState& run, const StopCause& cause);
  /// The safe stop after a fault or an operator stop; sets result's reason, message and safe_stop.
  void SafeStop(const StopCause& cause, CellRunResult& result);
  /// Throws StopRequested when a stop was requested and the run is not stopping already.
  void CheckStop();
  /// Holding: over the bin, down to the release height (in F/T-read steps when `ft_usable`:
  /// DescendIntoBin), open, up; says what it did and could not.
  std::string ReturnHeldTubeToBin(SafeStopOutcome& outcome, bool ft_usable);
  /// The release pose over the bin's middle, x_Tcp turned (about the vertical) along the bin's long
  /// side so that the held tube hangs along it.
  /// After the safe stop opened over the bin: what still hangs on the tool (against
  /// caught_reference_, above F_tol; an F/T that does not answer cannot say it fell off), or
  /// nullopt when nothing was caught or it fell off. Never throws.
  std::optional<std::string> LoadStillCaught();
  Eigen::Isometry3d SafeReleasePose(const Eigen::Isometry3d& X_BinTcpNow) const;
  /// From straight above X_BinTcpRelease down towards it in safe_release_step steps, reading the
  /// F/T after each: returns the pose where the held tube came to rest on the heap (the load
  /// changed by more than half a tube's weight, or the readings disagree), or X_BinTcpRelease once
  /// there. An F/T that does not answer ends the readings: straight down. `rest` says which. Robot
  /// errors are thrown.
  Eigen::Isometry3d DescendIntoBin(const Eigen::Isometry3d& X_BinTcpRelease, std::string* rest);
  /// One F/T measurement during the safe stop; nullopt when it fails. With `pressing`, readings
  /// that keep disagreeing set it (the held tube pressing on something) instead of `rest`.
  std::optional<devices::WrenchReading> SafeStopReading(std::string* rest, bool* pressing = nullptr);

  // One picking attempt (cell_attempt.cc): approach, reference, grasp, lift, analyze, then place,
  // resolve or put back.
  /// Why plan `rank` of `response` cannot be executed: it does not fit this controller's cell
  /// (CellFrameProblem, when params.cell_check is on), a pose is beyond the robot's limits, or
  /// ToolClearanceProblem (when that check is on); nullopt when it can.
  std::optional<PlanSkip> ExecutionProblem(const v1::PlanPickResponse& response, int rank) const;
  PlanPoses PosesOf(const v1::PickPlan& plan, int rank) const;
  /// The commands ExecutePlan gives for `poses` from home when one tube is held (DryRun).
  std::vector<PlannedMotion> PlannedMotions(const PlanPoses& poses, double opening_width) const;
  void ExecutePlan(const v1::PickPlan& plan, int rank, Attempt& attempt);
  void Approach(const Eigen::Isometry3d& X_BinTcpPreGrasp, double opening_width, Attempt& attempt);
  devices::WrenchReading TakeReference(Attempt& attempt);
  /// Down to the grasp pose and close; whether the gripper reports an object.
  bool Grasp(const Eigen::Isometry3d& X_BinTcpGrasp, Attempt& attempt);
  void ReleaseFailedGrasp(const Eigen::Isometry3d& X_BinTcpGrasp, const Eigen::Isometry3d& X_BinTcpPreGrasp,
                          const devices::WrenchReading& reference, Attempt& attempt);
  /// Along the plan's waypoints; returns the lift pose.
  Eigen::Isometry3d Lift(const std::vector<Eigen::Vector3d>& waypoints_Bin, Attempt& attempt);
  /// The reading at the lift pose (into `lifted`) and its analysis.
  v1::AnalyzeWrenchResponse AnalyzeLift(const devices::WrenchReading& reference,
                                        const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt,
                                        devices::WrenchReading* lifted);
  /// Adds the lift's tube_ratio to the cell's and records a doubt about tube.mass (CheckTubeMass).
  void CheckLiftWeights(double tube_ratio, Attempt& attempt);
  /// SINGLE: place; NONE: release; MULTIPLE: nullopt (resolve).
  std::optional<AttemptResult> Conclude(v1::HeldOutcome outcome, const Eigen::Isometry3d& X_BinTcpPlace,
                                        const devices::WrenchReading& reference, Attempt& attempt);
  AttemptResult Resolve(const v1::AnalyzeWrenchResponse& analysis, const devices::WrenchReading& reference,
                        const devices::WrenchReading& lifted, const PlanPoses& poses,
                        const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt);
  /// Resolution motion `m` moved by `shift` (lift pose → hold pose) or, with resolution_rest_load,
  /// let down first (LowerToRest, no lower than X_BinTcpLowest) and turned there; back to the hold
  /// pose, a new reading (into `after`) and its analysis.
  v1::AnalyzeWrenchResponse ResolutionMotion(const v1::ResolutionMotion& motion, int m,
                                             const devices::WrenchReading& reference,
                                             const Eigen::Translation3d& shift,
                                             const Eigen::Isometry3d& X_BinTcpHold,
                                             const Eigen::Isometry3d& X_BinTcpLowest, Attempt& attempt,
                                             devices::WrenchReading* after);
  /// Where several tubes not freed are put back: the lift pose, moved inward as far as their centre
  /// of mass (from `held`, the last reading, taken with the lift pose's orientation) needs to lie
  /// put_back_margin inside the walls (PlanPutBackShift); recorded under record["resolution"].
  Eigen::Isometry3d PutBackPose(const devices::WrenchReading& reference, const devices::WrenchReading& held,
                                const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt) const;
  void Place(const Eigen::Isometry3d& X_BinTcpPlanned, const devices::WrenchReading& reference,
             Attempt& attempt);
  /// The planned place pose, raised where the tool (closed on the tube) would come nearer to the
  /// place surface than tool.margin (place_surface_height); recorded as record["place_raised"].
  Eigen::Isometry3d ClearOfThePlaceSurface(const Eigen::Isometry3d& X_BinTcpPlanned, Attempt& attempt) const;
  /// From the current pose straight down to the place pose in steps of place_step, reading the F/T
  /// after each; stops where the tube no longer weighs a tube (it rests on the place surface).
  void DescendOntoPlace(const Eigen::Isometry3d& X_BinTcpPlace, const devices::WrenchReading& reference,
                        Attempt& attempt);
  /// The gripper still reports the object (Robotiq gOBJ 2); throws TubeLost naming `where` if not.
  void CheckStillHolding(const char* where, Attempt& attempt);
  /// The load at the pose above the place pose still weighs a tube; throws TubeLost if not.
  /// Reads the load above the place pose into record["wrench"][key]; false when it is lighter than
  /// a tube.
  bool LoadBeforePlace(const devices::WrenchReading& reference, const char* key, Attempt& attempt,
                       v1::AnalyzeWrenchResponse* check);
  /// LoadBeforePlace, except that a measurement whose readings keep disagreeing (the F/T's
  /// device_fault: the held tube pressing on the place surface) is recorded under
  /// record["wrench"][key + "_unsettled"] and gives nullopt.
  std::optional<bool> LoadBeforePlaceUnlessPressing(const devices::WrenchReading& reference, const char* key,
                                                    Attempt& attempt, v1::AnalyzeWrenchResponse* check);
  /// The tube is gone: record where and when, open (the fingers closed on nothing), home.
  void RecordLost(const TubeLost& lost, Attempt& attempt);
  void ReleaseEmpty(Attempt& attempt);
  /// Several tubes held after every resolution motion, the TCP at X_BinTcpPutBack (PutBackPose):
  /// lower them towards release_height above the grasp's height in steps (LayDown), open where they
  /// rest, back up.
  void PutBack(const Eigen::Isometry3d& X_BinTcpGrasp, const Eigen::Isometry3d& X_BinTcpPutBack,
               const devices::WrenchReading& reference, Attempt& attempt);
  /// From X_BinTcpFrom (where the TCP is) straight down to X_BinTcpRelease in steps of put_back_step, reading
  /// the F/T after each; stops where less than half a tube's weight still hangs on the tool (the tubes rest
  /// on the heap); readings that disagree (a tangle swinging, sliding on the heap) go on down. Returns where
  /// it stopped.
  Eigen::Isometry3d LayDown(const Eigen::Isometry3d& X_BinTcpFrom, const Eigen::Isometry3d& X_BinTcpRelease,
                            const devices::WrenchReading& reference, Attempt& attempt);
  /// Where a descent got lighter, and the load that still hung on the tool there, N.
  struct Lighter {
    Eigen::Isometry3d X_BinTcp;
    double load = 0.0;
  };
  /// From X_BinTcpFrom (where the TCP is) straight down towards X_BinTcpTo in steps of put_back_step,
  /// reading the F/T after each, until less than `below` newtons hang on the tool; readings that
  /// disagree are recorded (the step's height under record["wrench"][unsettled_key]) and go on down.
  /// The step where it got lighter; nullopt when it got to X_BinTcpTo without.
  std::optional<Lighter> DescendUntilLighter(const Eigen::Isometry3d& X_BinTcpFrom,
                                             const Eigen::Isometry3d& X_BinTcpTo,
                                             const devices::WrenchReading& reference, double below,
                                             const char* unsettled_key, Attempt& attempt);
  /// resolution_rest_load: from the hold pose down towards X_BinTcpLowest (DescendUntilLighter)
  /// until less than that many tube weights hang on the tool; the way down from the hold pose,
  /// recorded under record["resolution"]["lowered"].
  Eigen::Translation3d LowerToRest(const Eigen::Isometry3d& X_BinTcpHold,
                                   const Eigen::Isometry3d& X_BinTcpLowest,
                                   const devices::WrenchReading& reference, Attempt& attempt);
  /// Before the tool goes home empty-handed (after a failed grasp, a put-back, a nudge, the place):
  /// a reading against `reference` (the same gripper opening and, but for a turn about the
  /// vertical, orientation) that must weigh nothing, into record["wrench"][key]. A tube caught on
  /// the pads or the housing is not carried home: the tool goes down to `X_BinTcpShed` (where it
  /// just opened: inside the bin, or the place pose) and back up once; still loaded, it throws
  /// CellFault (ft_sensor, unexpected_load) with held_ unknown (and, after the place, "placed"
  /// false), so the safe stop carries it over the bin's middle, lowers it and opens there.
  void CheckToolEmpty(const devices::WrenchReading& reference, const std::string& key,
                      const Eigen::Isometry3d& X_BinTcpShed, Attempt& attempt);
  /// One tube's weight, N: tube.mass · the profile's gravity.
  double TubeWeight() const;
  /// The force `now` adds to `reference` (the same opening and orientation: whatever the tilt, a
  /// caught tube adds its weight), newtons, when it is more than F_tol of Algorithm 3 (not noise);
  /// nullopt otherwise.
  std::optional<double> LoadOnTool(const devices::WrenchReading& reference,
                                   const devices::WrenchReading& now) const;
  /// The nudge skill's motions (kNudge), from home back to home; the fingers close before the tool
  /// goes down and open only once it is back above the walls.
  void ExecuteNudge(const NudgePlan& plan, Attempt& attempt);
  /// Straight up to the transit height (when lower), then open the gripper there.
  void OpenAboveTheWalls(Attempt* attempt);
  void GoHome(Attempt* attempt);

  // Devices and planner calls (cell_device_calls.cc), each timed and its failures turned into
  // CellFault.
  devices::Capture Scan();
  /// Runs a robot motion through CallDevice and adds its wall and device time to `attempt`.
  template <typename Motion>
  void TimedRobotMotion(Attempt* attempt, const Motion& motion);
  void MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Attempt* attempt);
  void MoveThrough(const std::vector<Eigen::Vector3d>& waypoints_Bin, double speed, Attempt* attempt);
  /// Robot::Hold for `seconds` (the robot's time of the attempt counts it).
  void HoldStill(double seconds, Attempt* attempt);
  Eigen::Isometry3d CurrentPose();
  /// The poses TransitTo moves through from X_BinTcpFrom: up to transit height (if below it),
  /// across, down to X_BinTcpTo (if below it); the last is X_BinTcpTo.
  std::vector<Eigen::Isometry3d> TransitSegments(const Eigen::Isometry3d& X_BinTcpFrom,
                                                 const Eigen::Isometry3d& X_BinTcpTo) const;
  /// Up to transit height, across, down to `X_BinTcp`; `after_each` (if set) runs after every segment.
  void TransitTo(const Eigen::Isometry3d& X_BinTcp, Attempt* attempt,
                 const std::function<void()>& after_each = {});
  devices::GripperStatus CheckGripper(const devices::GripperStatus& status);
  void OpenGripper();
  devices::GripperStatus CloseGripper();
  /// Mean of params.ft_samples readings after the settle samples; readings off the median by more
  /// than the spike limits are dropped (half of them or more dropped: a fault).
  devices::WrenchReading ReadWrench();
  /// One reading; a timed-out one is read again (params.ft_read_retries).
  devices::WrenchReading ReadOneWrench();
  /// AnalyzeWrench's request for these readings at X_BinTcp, with the cell's tube mass and the
  /// controller's resolution variant.
  v1::AnalyzeWrenchRequest WrenchRequest(const devices::WrenchReading& reference,
                                         const devices::WrenchReading& current,
                                         const Eigen::Isometry3d& X_BinTcp) const;
  /// AnalyzeWrench on the planner; when it cannot be reached (UNAVAILABLE after the client's
  /// retries, DEADLINE_EXCEEDED) the same analysis runs here, and the record says so.
  v1::AnalyzeWrenchResponse Analyze(const devices::WrenchReading& reference,
                                    const devices::WrenchReading& current,
                                    const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt);

  void Enter(CellState state);
  nlohmann::json Truth() const;
  double DeviceNow() const;

  CellDevices devices_;
  PlannerClient& planner_;
  CellConfig cell_;
  CellControllerParams params_;
  RecordSink* sink_;
  std::function<double()> device_clock_;
  std::function<nlohmann::json()> annotator_;
  std::function<void(CellState)> observer_;
  CellState state_ = CellState::kStart;
  Held held_ = Held::kUnknown;
  /// Set by CheckToolEmpty when something stayed caught on the tool: the empty tool's reading, so
  /// that the safe stop can tell whether opening over the bin shed it.
  std::optional<devices::WrenchReading> caught_reference_;
  std::uint32_t round_ = 0;
  /// Codes of the planner's modeling warnings already logged (PlanPick logs each once).
  std::set<std::string> planner_warnings_seen_;
  /// tube_ratio of the most recent lifts analysed (tube_mass_check.limits.window of them), oldest
  /// first: CheckTubeMass's input.
  std::vector<double> lift_ratios_;
  bool tube_mass_doubt_said_ = false;
  /// A stop was requested (RequestStop); stop_why_ (under stop_mutex_) is set before it.
  std::atomic<bool> stop_requested_{false};
  mutable std::mutex stop_mutex_;
  std::string stop_why_;
  /// The run is in its safe stop (no further stop checks).
  bool stopping_ = false;
  /// The run has commanded a device that may move (servo on): before that a stop moves nothing.
  bool commanded_ = false;
  /// DryRun under way: nothing may move, not even in a safe stop.
  bool dry_run_ = false;
};

}  // namespace tubepick::cell
