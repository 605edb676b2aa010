#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"

namespace tubepick::cell {

/// The tool as boxes in the TCP frame (z down along the approach, y the closing direction), for
/// the controller's own check that it can execute a plan without driving the tool into the bin
/// (a protective stop ends the round). The defaults are a Robotiq 2F-85 as the simulated cell
/// models it (devices/sim SimGripperParams).
struct ToolGeometry {
  /// Pads: size along x_Tcp (along the tube), y_Tcp (closing) and z_Tcp, metres.
  Eigen::Vector3d finger_size{0.022, 0.010, 0.050};
  /// How far the fingertips reach past the TCP along z_Tcp, metres.
  double finger_tip_depth = 0.005;
  /// Housing box size (x, y, z in the TCP frame), metres, and the gap between the pads' top and
  /// the housing's bottom.
  Eigen::Vector3d housing_size{0.06, 0.13, 0.09};
  double housing_gap = 0.02;
  /// Distance kept from the bin's inner walls and floor, metres.
  double margin = 0.003;
};

/// Why the tool, opened to `opening` and at X_BinTcp_grasp moved through `waypoints` (relative
/// translations, bin axes), would touch a bin wall or the floor, or nullopt when it stays clear.
/// Only tool points below the wall top are checked (above it the tool is outside the bin's walls
/// by construction); the vertical approach from above is covered by the grasp pose itself, and
/// the straight segments between waypoints by their ends (the bin's inside is convex).
std::optional<std::string> ToolClearanceProblem(const CellConfig& cell, const ToolGeometry& tool,
                                                const Eigen::Isometry3d& X_BinTcp_grasp, double opening,
                                                const std::vector<Eigen::Vector3d>& waypoints);

}  // namespace tubepick::cell
