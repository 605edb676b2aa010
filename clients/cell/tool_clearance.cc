#include "clients/cell/tool_clearance.h"

#include <algorithm>
#include <limits>

namespace tubepick::cell {

std::optional<std::string> ToolClearanceProblem(const CellConfig& cell, const ToolGeometry& tool,
                                                const Eigen::Isometry3d& X_BinTcpGrasp, double opening,
                                                const std::vector<Eigen::Vector3d>& waypoints) {
  const std::optional<ToolClearanceIssue> issue =
      tubepick::ToolClearanceProblem(cell.bin, tool, X_BinTcpGrasp, opening, waypoints);
  if (!issue) return std::nullopt;
  return issue->ToString();
}

double ToolLowestZ(const ToolGeometry& tool, double opening, const Eigen::Isometry3d& X_BinTcp) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const ToolBox& box : ToolBoxes(tool, opening)) {
    for (int corner = 0; corner < 8; ++corner) lowest = std::min(lowest, (X_BinTcp * box.Corner(corner)).z());
  }
  return lowest;
}

}  // namespace tubepick::cell
