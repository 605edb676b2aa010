#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "clients/cell/tool_clearance.h"
#include "core/common/cell_config.h"
#include "tubepick/v1/planning.pb.h"

namespace tubepick::cell {

/// The nudge skill: when the planner models tubes but gives no plan the tool can execute (every
/// grasp would drive a pad or the housing into a bin wall), the controller drags a tube lying
/// along a wall towards the bin's middle and scans again. The gripper is closed, turned so that
/// the housing's narrow side (x_Tcp, 0.06 m) faces the wall, lowered onto the top of the tube
/// until the pads press `press_depth` into it, then moved horizontally away from the wall: the pads
/// drag (or roll) the tube along, since the pad friction exceeds the floor's.
struct NudgeParams {
  /// Nudge at all (false: a scan without an executable plan is only a rescan, as before).
  bool enabled = true;
  /// Nudges in one run (one bin).
  std::uint32_t max_nudges_per_bin = 6;
  /// A tube point whose axis is closer than this to a wall (xy) counts as lying along it, metres
  /// (a grasp across the tube needs 0.068 m for the 2F-85's housing).
  double near_wall_distance = 0.10;
  /// The push aims to bring the contact point this far from the wall, metres.
  double target_wall_distance = 0.15;
  /// Push distance = push_gain · (target_wall_distance − wall distance), clamped to
  /// [min_push, max_push]: a tube that rolls under the pad travels half the pad's way.
  double push_gain = 2.0;
  double min_push = 0.06;
  double max_push = 0.22;
  /// How far the pads' bottom goes below the tube's top, metres.
  double press_depth = 0.004;
  /// The closed tool keeps this far from the other modeled tubes (their cylinders, grown by their
  /// radius) on the way down to the press, along the push and on the way up, metres. A push that would
  /// come closer stops short; none when that leaves less than min_push: a tool driven into the heap
  /// meets tubes pinned by others, not a tube that slides.
  double tube_clearance = 0.005;
  /// The tool leans this far from the vertical, its tips towards the wall and its housing towards
  /// the middle, so the pads reach over a tube close to the wall while the housing stays clear,
  /// radians (rotation about y_Tcp; the robot allows up to 60°). 0.4 rad ≈ 23°.
  double tilt = 0.4;
  /// TCP speed of the push, m/s.
  double speed = 0.05;
  /// Sample spacing along the tube when looking for the contact point, metres.
  double sample_spacing = 0.02;
  /// A nudge whose contact lies within this of an earlier nudge's, with the tube as far from the
  /// wall, since tubes last moved otherwise (a pick, a put-back, a lost tube), would repeat a push
  /// that moved nothing there (a tube hanging over a wall, or caught): it is not done, and the scan
  /// says so. Metres; 0 = nudges repeat freely (up to max_nudges_per_bin).
  double repeat_radius = 0.005;
};

/// One planned nudge, bin frame.
struct NudgePlan {
  std::uint32_t tube_id = 0;
  /// Point on the tube's axis the pads press on, and its distance to the nearest wall.
  Eigen::Vector3d p_Bin_contact = Eigen::Vector3d::Zero();
  double wall_distance = 0.0;
  /// Unit horizontal push direction (away from the wall(s) the point lies along).
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  /// How far the TCP is moved from the contact point along `direction` for the tool to clear the
  /// wall, metres (the pads still cover the tube's top).
  double shift = 0.0;
  /// Push length, metres.
  double distance = 0.0;
  /// TCP at the bottom of the press (gripper closed, z_Tcp down, x_Tcp = direction).
  Eigen::Isometry3d X_BinTcpPress = Eigen::Isometry3d::Identity();
};

/// A nudge for one of `tubes` (the planner's modeled tubes, bin frame), or nullopt when no tube
/// lies along a wall or none can be pressed without the closed tool (ToolClearanceProblem, opening
/// 0) touching a wall or the floor at the press pose, along the push or on the way up
/// (`lift` metres), or without it coming within tube_clearance of another tube on its way down
/// (from the bin-frame height `transit_z`, where the closed tool comes from), back up to it, or
/// along at least min_push of the push (the push then stops there). Tubes are tried non-occluded first, then
/// by their distance to a wall (closest first); on a tube, the contact point is the sampled axis point along
/// a wall closest to the fraction {0.5, 0.3, 0.7}[try_index % 3] of its length (so repeated nudges of the
/// same tube push at different places). `tube_radius` is used for cylinders without a radius.
std::optional<NudgePlan> PlanNudge(const google::protobuf::RepeatedPtrField<v1::Tube>& tubes,
                                   const CellConfig& cell, const ToolGeometry& tool,
                                   const NudgeParams& params, double lift, double transit_z,
                                   std::uint32_t try_index);

/// Waypoints of the push and the lift after it, relative to X_BinTcpPress (for Robot::MoveThrough).
std::vector<Eigen::Vector3d> NudgePushWaypoints(const NudgePlan& plan);

}  // namespace tubepick::cell
