#include "clients/cell/tool_clearance.h"

namespace tubepick::cell {

std::optional<std::string> ToolClearanceProblem(const CellConfig& cell, const ToolGeometry& tool,
                                                const Eigen::Isometry3d& X_BinTcpGrasp, double opening,
                                                const std::vector<Eigen::Vector3d>& waypoints) {
  const std::optional<ToolClearanceIssue> issue =
      tubepick::ToolClearanceProblem(cell.bin, tool, X_BinTcpGrasp, opening, waypoints);
  if (!issue) return std::nullopt;
  return issue->ToString();
}

}  // namespace tubepick::cell
