#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "tubepick/v1/planning.pb.h"

namespace tubepick::cell {

/// The check of a plan's poses against the controller's own cell (its CellConfig) before any
/// motion: a planner configured with another cell (another bin size or sensor pose, another place
/// frame, clouds or cell in millimetres) must not drive the arm. Its plans are skipped with a reason
/// that names the pose, its value, the bound and the likely cause.
struct CellFrameCheckParams {
  /// Check at all (false: plans are only checked against the robot's limits and the tool clearance).
  bool enabled = true;
  /// The grasp must lie inside the bin's interior (floor to wall top; see grasp_above_walls), the
  /// pre-grasp pose and the lift waypoints above the floor and over the bin's inner footprint, each
  /// grown by this margin, metres.
  double bin_margin = 0.02;
  /// The grasp may also lie up to this far above the wall top (plus bin_margin), over the bin's
  /// inner footprint, for a cell whose heap is meant to rise above the walls (the modeling's crop
  /// box sees 0.3 m above them). 0 by default: a tube that high is as likely one leaning on a wall,
  /// partly outside the bin, as the top of a heap. In a simulated 20-tree bin (docs/ACCURACY.md)
  /// such a tree, grasped 0.12 m above the wall top with 0.3 allowed, caught on the wall on the way
  /// to the place (4437 N on the F/T) and ended in a safe stop; refused, it is named for the
  /// operator.
  double grasp_above_walls = 0.0;
  /// The place frame that the plan's place pose implies (the planner lays the tube frame it
  /// estimated on its own place frame) must lie this close to the controller's
  /// (CellConfig::place), metres. The controller has the tube's model, not the planner's points:
  /// where along the tube the planner put the frame's origin (the points' centroid, or the grasp
  /// point) is only known to lie between the model's ends, so a place frame shifted along its own
  /// x axis (the tube's direction) by less than half the tube is not told apart. Without a modeled
  /// tube in the answer the place TCP must lie within this plus the tube's length (cell
  /// tube.length; the bin's diagonal when 0) of the place frame.
  double place_position_tolerance = 0.05;
  /// ... and be turned from it by at most this, radians. Two checks: the tilt (a yaw-only
  /// placement, the planner's placement.yaw_only default, turns the held tube about the vertical
  /// only, so the place frame's z seen from the TCP at the place must be the bin's z seen from the
  /// TCP at the grasp), and, when the modeled tube has a clear direction, the whole turn of the
  /// implied place frame (a tube is symmetric end to end: a half turn about z is the same frame).
  double place_rotation_tolerance = 0.35;

  /// @throws InvalidArgument naming the field ("cell_check.bin_margin") and its value.
  void Validate() const;
};

/// The poses of one plan the check looks at, bin frame.
struct PlanFrameInput {
  Eigen::Isometry3d X_BinTcpGrasp = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_BinTcpPreGrasp = Eigen::Isometry3d::Identity();
  /// The lift: TCP translations from the grasp pose, bin axes.
  std::vector<Eigen::Vector3d> waypoints_Bin;
  /// The plan's place pose, if it has one.
  std::optional<Eigen::Isometry3d> X_BinTcpPlace;
  /// The planner's model of the plan's tube (PlanPickResponse::tubes), if the answer has it.
  const v1::Tube* tube = nullptr;
};

/// Why the plan does not fit `cell` (bin, place frame), as one line starting "cell check: ", or
/// nullopt when it fits (or params.enabled is false).
std::optional<std::string> CellFrameProblem(const CellConfig& cell, const CellFrameCheckParams& params,
                                            const PlanFrameInput& plan);

}  // namespace tubepick::cell
