#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/planning/tool_clearance.h"

namespace tubepick::cell {

/// The tool as boxes in the TCP frame (z down along the approach, y the closing direction): the
/// planner's own tool model (core/planning/tool_clearance.h ToolParams, the `planning.tool` params
/// section), so the controller checks plans and its own moves with exactly the geometry the planner
/// filters grasps with. Defaults: a Robotiq 2F-85 as the simulated cell models it (devices/sim
/// SimGripperParams). ToolParams::check is not used by the controller (see
/// CellControllerParams::check_tool_clearance).
using ToolGeometry = ToolParams;

/// Why the tool, opened to `opening` and at X_BinTcpGrasp moved through `waypoints` (relative
/// translations, bin axes), would touch a bin wall or the floor, or nullopt when it stays clear:
/// tubepick::ToolClearanceProblem on the cell's bin, as one line.
std::optional<std::string> ToolClearanceProblem(const CellConfig& cell, const ToolGeometry& tool,
                                                const Eigen::Isometry3d& X_BinTcpGrasp, double opening,
                                                const std::vector<Eigen::Vector3d>& waypoints);

/// The lowest point (bin z) of the tool opened to `opening` at X_BinTcp: the lowest corner of its
/// boxes (ToolBoxes), metres.
double ToolLowestZ(const ToolGeometry& tool, double opening, const Eigen::Isometry3d& X_BinTcp);

}  // namespace tubepick::cell
