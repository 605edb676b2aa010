#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "clients/cell/cell_frame_check.h"
#include "clients/cell/nudge.h"
#include "clients/cell/tool_clearance.h"
#include "clients/cell/wall_watch.h"
#include "core/common/cell_config.h"
#include "core/wrench/tube_mass_check.h"
#include "devices/device_error.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick::cell {

/// The controller's check of its lifts' weights against tube.mass (CheckTubeMass's limits). A cell
/// that lifts parts of different weights on purpose turns it off.
struct LiftWeightCheckParams {
  bool enabled = true;
  TubeMassCheckParams limits;
};

/// Everything the cell controller decides by itself: speeds, heights, the planner options, the
/// attempt limits and the timeouts. Every field has a default that suits the simulated cell and the
/// thesis' setup (§5.3); poses are X_BinTcp (TCP in the bin frame, z down along the approach).
/// As YAML: ParseCellControllerParams / LoadCellControllerParams / DumpCellControllerParams
/// (cell_controller_config.h; the keys are these field names, durations in seconds).
struct CellControllerParams {
  // --- motion ---
  /// Free moves between poses (home, transit, above the place frame), m/s.
  double transit_speed = 0.25;
  /// Pre-grasp → grasp and above-place → place, m/s.
  double approach_speed = 0.05;
  /// Along the plan's waypoints after the grasp, m/s; the planner's trajectory simulation drives the
  /// tube at the same speed (physics::TrajectorySimParams::gripper_speed, §5.2.3.2).
  double lift_speed = 0.1;
  /// Resolution rotations and the return to the lift pose, m/s of the TCP (the robot's speed unit).
  double resolution_speed = 0.1;
  /// Several tubes held: before the resolution rotation, carry them (at lift_speed, at the lift
  /// height) so that the payload's centre of mass, estimated from the torque (PlanResolutionHold),
  /// is over the bin's middle, with the TCP at least resolution_wall_margin inside the inner walls;
  /// the rotation then runs there, so that what it frees falls into the bin. Unresolved tubes are
  /// carried back to the lift pose before they are put back. On generated set-C pvc bins
  /// (`tubepick resolution-trials`) this halved the tubes that ended outside the bin.
  bool resolution_hold_over_bin = true;
  double resolution_wall_margin = 0.15;
  /// Each resolution motion pauses this long at its tilt (Robot::Hold) before turning back, seconds:
  /// a hose with rubber's friction slides off the tilted tube slowly, and turning back at once
  /// hooks it again. On generated set-C bins (`tubepick resolution-trials --dwell`) 1.5 s freed 11
  /// of 24 rubber and 22 of 31 pvc double picks against 9 and 21 without, no tube more outside the
  /// bin (docs/ACCURACY.md). 0 = turn back at once (the thesis).
  double resolution_dwell = 1.5;
  /// A motion that left several tubes: the next one is the first motion the planner gives for the
  /// reading taken at the hold pose after it (about the torque axis the tangle shows now), turned
  /// about the TCP there, rather than the next motion planned from the lift's reading; as many
  /// motions as that plan had. On generated set-C bins (`tubepick resolution-trials --replan`, the
  /// same double picks either way) the second motion then freed 6 of 8 tangles of 20 pvc trees
  /// (against 4 about the perpendicular) and 1 of 13 of 10 rubber trees (against 0), and lost none
  /// (docs/ACCURACY.md). false: the lift plan's motions in order (torque_axis_then_perpendicular's
  /// perpendicular second).
  bool resolution_replan = true;
  /// With resolution_replan, after the plan's motions: up to this many more while several tubes
  /// still hang, each the first motion planned from the latest reading at the hold pose. On
  /// generated set-C bins (`tubepick resolution-trials --extra-motions 2`, the same double picks)
  /// two more freed 1 of the 13 tangles (2 pvc, 11 rubber) the plan's two left, at about 10 s each
  /// tangle not freed (docs/ACCURACY.md): off by default. 0 = the plan's motions only; at most
  /// kMaxResolutionExtraMotions.
  std::uint32_t resolution_extra_motions = 0;
  /// Each motion turns, pauses and reads (about 10 s): more than a few is a mistake, not patience.
  static constexpr std::uint32_t kMaxResolutionExtraMotions = 10;
  /// Before each resolution motion, the tangle is let down from the hold pose in put_back_step
  /// steps, reading the F/T at each, until less than this many tube weights hang on the tool (the
  /// tubes hooked on the grasped one resting on the heap), no lower than release_height above the
  /// grasp; the motion turns there, and the tool goes back up to the hold pose for the reading. A
  /// hose hanging wholly from the grasped one keeps its hook under its own weight; resting, it
  /// slides off. On generated set-C bins (`tubepick resolution-trials --rest-load 1.5`, the same
  /// double picks either way) 1.5 freed 27 of 47 rubber tangles against 20 turned at the hold pose
  /// (9 won, 2 lost), but 9 of 12 pvc ones against 11: a stiff tree resting on the heap stays in the
  /// hook (docs/ACCURACY.md). 0 = turn at the hold pose (the default; pvc); otherwise more than 1
  /// (the grasped tube alone weighs one) and at most kMaxResolutionRestLoad.
  double resolution_rest_load = 0.0;
  static constexpr double kMaxResolutionRestLoad = 10.0;
  /// Pre-grasp pose: this far back from the grasp along the approach direction, metres.
  double approach_height = 0.10;
  /// Transit moves happen at least this far above the bin's wall top, metres.
  double transit_clearance = 0.30;
  /// Several tubes that the resolution could not shake off are lowered back to this height above
  /// the grasp point before the gripper opens, metres.
  double release_height = 0.03;
  /// They are put back where they were lifted, unless their centre of mass (from the F/T's torque
  /// after the last resolution motion, PlanPutBackShift) lies less than this inside a wall: then
  /// the put-back pose moves inward, only as far as that takes. Lowered at a wall, a tangle lies
  /// down over it (a simulated 20-tree bin lost two trees so, its centre of mass 1 cm inside).
  /// Metres.
  double put_back_margin = 0.15;
  /// The put-back's way down goes in steps of at most this, reading the F/T after each: where the
  /// tubes rest (less than half a tube's weight still hangs on the tool), the gripper opens there;
  /// readings that disagree (a tangle swinging or sliding on the heap) go on down. Also at the lift
  /// pose: what hangs under the tube grasped came up from elsewhere, and lowered in one move to the
  /// grasp height it was pushed on through the heap (a simulated 20-tree bin lost a tree over a
  /// wall so). Lowered until the heap takes the load, not let go at the first contact: a tangle
  /// dropped as soon as one arm touched a low heap threw a tree onto a wall's top. 0 = one move.
  /// Metres.
  double put_back_step = 0.02;
  /// Safe stop while holding a tube: the TCP goes over the bin's middle and down to this height
  /// above the bin floor before the gripper opens (below the wall top: the tube falls inside),
  /// metres.
  double safe_release_height = 0.15;
  /// The safe stop's way down to safe_release_height goes in steps of at most this, reading the
  /// F/T after each; where the load differs from the one over the bin by more than half a tube's
  /// weight, or the readings disagree, the held tube rests on the heap (or the tool touches it) and
  /// the gripper opens there. An F/T that does not answer: straight down. 0 = one move. Metres. In
  /// a simulated 20-tree bin the one move pressed the held tree into the heap with over 1000 N.
  double safe_release_step = 0.03;
  /// The place pose is approached from this far above it, metres.
  double place_approach_height = 0.10;
  /// The load above the place pose weighs less than a tube while the gripper still holds: the tube
  /// may rest on the place surface (a modeled tube that missed a branch is placed lower than it
  /// hangs). The TCP then rises this much more and reads again; only a load still missing there is
  /// a lost tube. 0 = no second reading. Metres.
  double place_recheck_height = 0.20;
  /// From above the place pose down to it, the TCP goes in steps of at most this, reading the
  /// F/T after each; where the held tube no longer weighs a tube (it rests on the place surface: a
  /// part the model missed hangs lower than the model), the descent stops and the gripper opens
  /// there instead of pushing the tube down to the planned pose. 0 = one move. Metres. In the
  /// simulated 20-tree bins (docs/ACCURACY.md) the planned descent pressed held trees on the
  /// place zone with 50-200 N.
  double place_step = 0.02;
  /// Height (bin z) of the surface the place zone's tubes are laid on. A planned place pose that
  /// would bring the tool (`tool`, closed on the tube) nearer to it than tool.margin is raised
  /// until it clears (the planner places the tube's frame, not the tool: a tube grasped where it
  /// lay lowest is placed with the fingers lowest). 0 = the bin floor's level, the simulated
  /// cell's ground. In a simulated 20-tree bin (docs/ACCURACY.md) a planned place pose put a
  /// finger 2 mm into the ground: a protective stop with the tree held.
  double place_surface_height = 0.0;
  /// Where the robot waits while the bin is scanned (out of the scanner's view). Absent: above the
  /// cell's placement frame at transit height, TCP pointing down.
  std::optional<Eigen::Isometry3d> X_BinHome;

  /// Plans whose tool path would touch a bin wall or the floor (ToolClearanceProblem) are skipped
  /// before execution: a protective stop would end the round.
  bool check_tool_clearance = true;
  ToolGeometry tool;
  /// The nudge skill for a scan whose tubes have no executable plan (see NudgeParams); it needs
  /// check_tool_clearance (its moves are checked with `tool`).
  NudgeParams nudge;
  /// Every plan's grasp, pre-grasp, lift waypoints and place pose are checked against this
  /// controller's own cell (its bin and place frame) before any motion; a plan that does not fit
  /// is skipped with the reason (CellFrameCheckParams): a planner configured with another cell
  /// (bin size, place frame, millimetres) must not drive the arm.
  CellFrameCheckParams cell_check;

  // --- gripper ---
  /// Closing speed (m/s) and force (N) (Robotiq 2F-85: 0.02-0.15 m/s, 20-235 N).
  double gripper_speed = 0.1;
  double gripper_force = 60.0;

  // --- force/torque ---
  /// Readings discarded before each F/T measurement: a wait for the payload to stop swinging
  /// (the thesis' WaitSkill; the simulated sensor averages 0.05 s per reading).
  std::uint32_t ft_settle_samples = 4;
  /// Readings averaged for each F/T measurement (reference and after the lift).
  std::uint32_t ft_samples = 5;
  /// Further tries of one reading that timed out (a lost RDT datagram) before it is a fault.
  std::uint32_t ft_read_retries = 2;
  /// A reading whose force (N) or torque (N·m) is farther than this from the measurement's median
  /// is a spike and dropped; half of the readings or more dropped is a fault.
  double ft_spike_force = 2.0;
  double ft_spike_torque = 0.2;
  /// Further measurements (settle samples, then ft_samples readings) after one whose readings
  /// mostly disagreed, before that is a fault: a payload still swinging settles, a loose cable or
  /// a saturated gauge does not (in the simulated set-C rounds one such measurement was steady at
  /// the next try; one that stayed off through three still safe-stopped its round, docs/ACCURACY.md).
  std::uint32_t ft_unsettled_retries = 2;
  /// Whether the lifts' weights still fit the cell's tube.mass (CheckTubeMass): a doubt is logged once
  /// and recorded with every attempt from then on; Algorithm 3's decisions are unchanged.
  LiftWeightCheckParams tube_mass_check;
  /// Tubes a scan shows hanging over a wall that the next scan no longer shows, though no attempt
  /// took them, may have fallen out of the bin: logged, recorded and named on the round's line.
  WallWatchParams wall_watch;

  // --- scanner ---
  /// Further scans after a scan that timed out or returned no point, before it is a fault.
  std::uint32_t scan_retries = 2;

  // --- planner ---
  /// Parameter profile sent with PlanPick ("" = the server's).
  std::string profile;
  /// Seed of the first PlanPick; scan k sends seed + k, so a rescan of an unchanged bin can give
  /// another model (RANSAC) and a run is still reproducible.
  std::uint64_t seed = 1;
  /// Plans requested per scan (0 = all); more plans leave alternatives when the best ones are
  /// skipped by the tool clearance check.
  std::uint32_t max_plans = 30;
  /// Plans executed on one scan when grasps close on nothing (then rescan).
  std::uint32_t max_plans_per_scan = 2;
  /// A plan whose grasp point lies within this distance of a grasp that closed on nothing or lifted
  /// nothing since tubes last moved (a pick, a put-back, a lost tube, a nudge) is skipped (check
  /// "failed_grasp"), metres: the bin is unchanged by such an attempt, and the same grasp fails the same way
  /// (4 lifts of a rubber branch pinned under a tree, 3 mm apart, in one simulated round). 0 = retry them.
  double failed_grasp_radius = 0.03;
  bool disable_simulation = false;
  /// Resolution rotation requested from AnalyzeWrench (UNSPECIFIED = the server's).
  v1::ResolutionVariant resolution_variant = v1::RESOLUTION_VARIANT_UNSPECIFIED;
  /// Per-try deadlines of the planner calls.
  std::chrono::milliseconds plan_deadline{180'000};
  std::chrono::milliseconds analyze_deadline{10'000};

  // --- limits ---
  /// Picking attempts (grasp executions) since the last successful pick.
  std::uint32_t max_attempts_per_tube = 4;
  /// Picking attempts in one run (one bin).
  std::uint32_t max_attempts_per_bin = 60;
  /// Consecutive scans or attempts that did not pick a tube (no plan, empty grasp, nothing or
  /// several lifted).
  std::uint32_t max_consecutive_failures = 6;

  // --- the bin ---
  /// Tubes a bin holds when its round starts; 0 = not known. When known, a round that finds the bin
  /// empty with fewer tubes placed says how many are unaccounted for (CellRunResult::
  /// tubes_unaccounted): a tube that left the bin where no scan of it sees is otherwise a silent
  /// "bin empty". In the simulated cell, `--tubes`.
  std::uint32_t tubes_per_bin = 0;

  // --- timeouts ---
  devices::Timeout scanner_timeout{30'000};
  /// One robot motion (the longest: a lift of ~0.4 m at lift_speed, or a transit).
  devices::Timeout robot_timeout{60'000};
  devices::Timeout gripper_timeout{10'000};
  devices::Timeout ft_timeout{2'000};

  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

/// Where a resolution's next motion comes from (NextResolutionMotion).
enum class ResolutionMotionSource {
  kPlan,     ///< the lift plan's motion of that index
  kReading,  ///< the first motion planned from the latest reading at the hold pose
  kNone,     ///< no more motions: the tubes go back into the bin
};

/// The resolution's motion number `m` (from 0) after a lift plan of `planned` motions, when the
/// latest reading at the hold pose (after motion m - 1) did or did not plan a motion of its own:
/// with resolution_replan that one, else the plan's m-th; past the plan's, up to
/// resolution_extra_motions more only from readings (none without a plan). The controller
/// (CellController::Resolve) and `tubepick resolution-trials` both follow it.
ResolutionMotionSource NextResolutionMotion(const CellControllerParams& params, std::size_t m,
                                            std::size_t planned, bool reading_has_motion);

/// Home pose of `params` for `cell` (see CellControllerParams::X_BinHome).
Eigen::Isometry3d HomePose(const CellControllerParams& params, const CellConfig& cell);
/// Height of transit moves in the bin frame: wall top + transit_clearance, metres.
double TransitHeight(const CellControllerParams& params, const CellConfig& cell);
/// The poses between `X_BinTcpFrom` and `X_BinTcpTo` (straight below it) where a descent in steps
/// of at most `step` stops, top down, neither end included; none when step is 0.
std::vector<Eigen::Isometry3d> DescentSteps(double step, const Eigen::Isometry3d& X_BinTcpFrom,
                                            const Eigen::Isometry3d& X_BinTcpTo);
/// The planned place pose, raised until the tool closed on a tube of `tube_radius` keeps
/// tool.margin above place_surface_height (ToolLowestZ of its boxes); unchanged when it does.
Eigen::Isometry3d PlacePoseClearOfTheSurface(const CellControllerParams& params, double tube_radius,
                                             const Eigen::Isometry3d& X_BinTcpPlanned);
/// The poses between `X_BinTcpFrom` (straight above the place pose) and `X_BinTcpPlace` where the
/// place descent stops to read the F/T (place_step), top down, neither end included.
std::vector<Eigen::Isometry3d> PlaceDescentSteps(const CellControllerParams& params,
                                                 const Eigen::Isometry3d& X_BinTcpFrom,
                                                 const Eigen::Isometry3d& X_BinTcpPlace);

}  // namespace tubepick::cell
