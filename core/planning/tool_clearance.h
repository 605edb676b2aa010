#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/cell_config.h"

namespace tubepick {

/// The gripper as boxes in the TCP frame (z_Tcp down along the approach, y_Tcp the closing
/// direction, x_Tcp along the grasped tube), for the tool-clearance test: a grasp is executable
/// only when the pads and the housing stay inside the bin's walls and above its floor. Defaults:
/// a Robotiq 2F-85 as devices/sim models it (SimGripperParams).
struct ToolParams {
  /// Skip grasps whose tool would touch a bin wall or the floor (ToolClears).
  bool check = true;
  /// One pad's size along x_Tcp (along the tube), y_Tcp (closing) and z_Tcp, metres. The pads sit
  /// at y_Tcp = ±(opening + size.y)/2.
  Eigen::Vector3d finger_size{0.022, 0.010, 0.050};
  /// How far the fingertips reach past the TCP along z_Tcp (below the tube axis), metres.
  double finger_tip_depth = 0.005;
  /// Housing box size (x, y, z in the TCP frame), metres: centred on the TCP's z axis, its bottom
  /// housing_gap above the pads' top (finger_tip_depth − finger_size.z − housing_gap along z_Tcp).
  Eigen::Vector3d housing_size{0.06, 0.13, 0.09};
  double housing_gap = 0.02;
  /// Distance the tool keeps from the bin's inner walls and floor, metres.
  double margin = 0.003;
};

/// One of the tool's boxes, TCP frame (axis-aligned there).
struct ToolBox {
  /// "finger" or "housing".
  const char* part = "";
  Eigen::Vector3d centre_Tcp = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();

  /// Corner `k` (0..7; bits 0, 1, 2 pick the + side along x, y, z), TCP frame.
  Eigen::Vector3d Corner(int k) const {
    return centre_Tcp + Eigen::Vector3d((k & 1 ? 1 : -1) * half_size.x(), (k & 2 ? 1 : -1) * half_size.y(),
                                        (k & 4 ? 1 : -1) * half_size.z());
  }
};

/// The two pads and the housing of `tool` opened to `opening` (distance between the pads' inner
/// faces, metres), in the TCP frame.
std::array<ToolBox, 3> ToolBoxes(const ToolParams& tool, double opening);

/// Where the tool would touch the bin (ToolClearanceIssue::ToString gives one line).
struct ToolClearanceIssue {
  /// "finger" or "housing".
  std::string part;
  /// "+x", "-x", "+y", "-y" (a wall) or "floor".
  std::string surface;
  /// How far past the wall / floor less the margin, metres (> 0).
  double depth = 0.0;
  /// Index into the waypoints (0 when none were given).
  std::size_t waypoint = 0;
  /// The offending tool corner, bin frame.
  Eigen::Vector3d p_Bin = Eigen::Vector3d::Zero();

  /// "finger 0.012 m into the -y wall at waypoint 0 (point (0.015, -0.309, 0.057) m)".
  std::string ToString() const;
};

/// The first place the tool would touch the bin when opened to `opening` (distance between the
/// pads' inner faces, metres) at X_BinTcp and translated through `waypoints` (relative
/// translations, bin axes; empty = the pose alone), or nullopt when it stays clear. Only tool
/// corners below the wall top (bin.inner_size.z) are tested against the walls: above it the tool
/// is outside the walls' reach. A vertical approach from above is covered by the pose itself and
/// the straight segments between waypoints by their ends (the bin's inside is convex).
std::optional<ToolClearanceIssue> ToolClearanceProblem(const BinConfig& bin, const ToolParams& tool,
                                                       const Eigen::Isometry3d& X_BinTcp, double opening,
                                                       const std::vector<Eigen::Vector3d>& waypoints);

/// !ToolClearanceProblem(...): the tool stays inside the walls and above the floor.
bool ToolClears(const BinConfig& bin, const ToolParams& tool, const Eigen::Isometry3d& X_BinTcp,
                double opening, const std::vector<Eigen::Vector3d>& waypoints);

}  // namespace tubepick
