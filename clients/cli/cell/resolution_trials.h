#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "clients/cell/cell_controller_params.h"
#include "core/planning/trajectory_synthesis.h"
#include "core/wrench/wrench_params.h"
#include "devices/sim/sim_cell.h"

namespace tubepick::cli {

/// The tube a trial grasps, and where: in a generated bin, the highest tube that another tube
/// lies on (TubesLyingOn on the ground truth, as a planner's unsure plan would take it), grasped
/// at the middle of its flattest cylinder (at least 4 cm long, inclined less than 17°) nearest its
/// centre of mass. nullopt when no tube has another lying on it, or none has such a cylinder.
struct TrialGrasp {
  std::size_t tube = 0;
  std::size_t tubes_on_it = 0;
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
};
/// Tubes in `tried` are not chosen again.
std::optional<TrialGrasp> ChooseTrialGrasp(const devices::sim::SimCell& cell,
                                           const std::vector<std::size_t>& tried);

/// What happened on one trial with one resolution.
struct ResolutionTrial {
  /// The bin's seed.
  std::uint64_t seed = 0;
  /// Lifts made (each on another tube, ChooseTrialGrasp) until one held several tubes.
  std::uint32_t lifts = 0;
  /// The last lift's tube (index in the bin) and how many tubes lay on it.
  std::size_t tube = 0;
  std::size_t tubes_on_it = 0;
  /// The F/T said several tubes after the lift (Algorithm 3): the resolution was tried.
  bool multiple = false;
  /// Ground truth after the lift: tubes other than the grasped one hanging clear of the floor
  /// (every node above two radii).
  std::uint32_t others_lifted = 0;
  /// Motions executed (kPerpendicular has two).
  std::uint32_t motions_used = 0;
  /// How far the payload was moved to the hold pose, metres.
  double hold_shift = 0.0;
  /// With the controller's resolution_rest_load: how far below the hold pose the last motion
  /// turned, metres.
  double lowered = 0.0;
  /// Motions skipped because a waypoint lay beyond the robot's reach or wrist limits, as the
  /// controller skips them; and motions turned at the hold pose because they were beyond them only
  /// where the tangle was let down to (resolution_rest_load).
  std::uint32_t beyond_limits = 0;
  std::uint32_t lowered_beyond_limits = 0;
  /// The F/T said one tube after a motion.
  bool freed = false;
  /// Ground truth after 2 s of rest at the end (holding the tube when freed, else after putting
  /// them back as the controller does): the grasped tube still held; tubes outside the bin (a
  /// freed tube must fall back into the bin).
  bool tube_held = false;
  std::uint32_t others_outside = 0;
  /// Several tubes not freed and put back: how far the put-back pose lay from the lift pose
  /// (PlanPutBackShift), metres; and whether, opened and back up, the tool still carried more than
  /// half a tube's weight (a tube caught on the pads or the housing).
  double put_back_shift = 0.0;
  bool caught = false;
  /// Tubes outside the bin before the first lift (the generated drop can leave one on a wall).
  std::uint32_t outside_at_start = 0;
  /// The gripper closed on nothing, or the robot refused or stopped a motion: the message.
  std::string fault;
};

/// How a trial moves.
struct TrialParams {
  /// Lift before the reading, metres (the planner's upward_distance).
  double lift = TrajectoryParams{}.upward_distance;
  /// Lifts per bin until one holds several tubes.
  std::uint32_t max_lifts = 6;
  /// Run the resolution on a double pick; false: put it back at once (measures the put-back alone).
  bool resolve = true;
  /// The controller's speeds, approach and release heights, resolution hold
  /// (resolution_hold_over_bin: the payload brought over the bin's middle, PlanResolutionHold,
  /// before the rotation, the TCP resolution_wall_margin inside the walls), the pause at each
  /// motion's tilt (resolution_dwell), the motions after the first planned from the reading
  /// before them (resolution_replan, resolution_extra_motions) and where they turn
  /// (resolution_rest_load: let down from the hold pose in put_back_step steps until less than that
  /// many tube weights hang on the tool, at most to the grasp's height + release_height, turned
  /// there, back up to the hold pose for the reading).
  cell::CellControllerParams controller;
};

/// Runs one trial in a generated bin (`params`): up to max_lifts lifts, each of the tube
/// ChooseTrialGrasp gives (not one lifted before), grasped from 10 cm above, lifted at 0.1 m/s; the
/// F/T read there. A lift that holds one tube puts it back (lowered to 3 cm above the grasp,
/// opened); the first that holds several (Algorithm 3) gets the resolution of `wrench`
/// (WrenchParamsAtPose at the lift pose) at the hold pose (hold_over_bin), each motion at 0.1 m/s,
/// a pause at the tilt (resolution_dwell) and back to the hold pose, read again, until one tube is left, and
/// ends the trial (put back as the controller puts back several tubes, put_back_margin and put_back_step,
/// when none freed). Every variant meets the same double pick: the simulation is deterministic up to the
/// resolution. Same params ⇒ same trial.
ResolutionTrial RunResolutionTrial(const devices::sim::SimCellParams& params, const WrenchParams& wrench,
                                   const TrialParams& trial_params);
/// The same in a cell built by the caller (e.g. with explicit tubes).
ResolutionTrial RunResolutionTrial(devices::sim::SimCell& cell, const WrenchParams& wrench,
                                   const TrialParams& trial_params);

/// The options of `tubepick resolution-trials`.
struct ResolutionTrialsOptions {
  std::vector<std::string> materials = {"pvc", "rubber"};
  std::vector<std::string> variants = {"torque_axis", "torque_axis_negative", "perpendicular"};
  std::vector<double> angles_deg = {45.0};
  std::string shapes;  // empty: the material's thesis set
  std::uint32_t tubes = 10;
  std::uint32_t bins = 40;
  std::uint64_t seed = 1;
  TrialParams trial;
  std::uint32_t jobs = 2;
  std::string json_path;
};

/// Checks every option before a trial runs. @throws InvalidArgument naming the flag and its value.
void ValidateResolutionTrials(const ResolutionTrialsOptions& o);

/// `tubepick resolution-trials`: how often each resolution rotation frees the extra tube of a
/// double pick in the simulated cell, per material, variant and angle.
void AddResolutionTrialsCommand(CLI::App& app);

}  // namespace tubepick::cli
