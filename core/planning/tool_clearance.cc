#include "core/planning/tool_clearance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace tubepick {

std::array<ToolBox, 3> ToolBoxes(const ToolParams& tool, double opening) {
  const double finger_z = tool.finger_tip_depth - 0.5 * tool.finger_size.z();
  const double finger_y = 0.5 * (opening + tool.finger_size.y());
  const double housing_z =
      tool.finger_tip_depth - tool.finger_size.z() - tool.housing_gap - 0.5 * tool.housing_size.z();
  return {ToolBox{"finger", Eigen::Vector3d(0.0, finger_y, finger_z), 0.5 * tool.finger_size},
          ToolBox{"finger", Eigen::Vector3d(0.0, -finger_y, finger_z), 0.5 * tool.finger_size},
          ToolBox{"housing", Eigen::Vector3d(0.0, 0.0, housing_z), 0.5 * tool.housing_size}};
}

std::string ToolClearanceIssue::ToString() const {
  char buffer[200];
  if (surface == "floor") {
    std::snprintf(buffer, sizeof(buffer),
                  "%s %.3f m below the floor at waypoint %zu (point (%.3f, %.3f, %.3f) m)", part.c_str(),
                  depth, waypoint, p_Bin.x(), p_Bin.y(), p_Bin.z());
  } else {
    std::snprintf(buffer, sizeof(buffer),
                  "%s %.3f m into the %s wall at waypoint %zu (point (%.3f, %.3f, %.3f) m)", part.c_str(),
                  depth, surface.c_str(), waypoint, p_Bin.x(), p_Bin.y(), p_Bin.z());
  }
  return buffer;
}

std::optional<ToolClearanceIssue> ToolClearanceProblem(const BinConfig& bin, const ToolParams& tool,
                                                       const Eigen::Isometry3d& X_BinTcp, double opening,
                                                       const std::vector<Eigen::Vector3d>& waypoints) {
  const std::array<ToolBox, 3> boxes = ToolBoxes(tool, opening);
  const Eigen::Vector3d half_bin = 0.5 * bin.inner_size;
  const double wall_top = bin.inner_size.z();
  const std::size_t n = std::max<std::size_t>(1, waypoints.size());
  for (std::size_t w = 0; w < n; ++w) {
    Eigen::Isometry3d X = X_BinTcp;
    if (!waypoints.empty()) X.translation() += waypoints[w];
    for (const ToolBox& box : boxes) {
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d p = X * box.Corner(corner);
        if (p.z() < tool.margin) return ToolClearanceIssue{box.part, "floor", tool.margin - p.z(), w, p};
        if (p.z() >= wall_top) continue;
        const double past_x = std::abs(p.x()) - (half_bin.x() - tool.margin);
        const double past_y = std::abs(p.y()) - (half_bin.y() - tool.margin);
        if (past_x > 0.0 || past_y > 0.0) {
          const bool x_wall = past_x >= past_y;
          const bool positive = (x_wall ? p.x() : p.y()) > 0.0;
          std::string surface = std::string(positive ? "+" : "-") + (x_wall ? "x" : "y");
          return ToolClearanceIssue{box.part, std::move(surface), x_wall ? past_x : past_y, w, p};
        }
      }
    }
  }
  return std::nullopt;
}

bool ToolClears(const BinConfig& bin, const ToolParams& tool, const Eigen::Isometry3d& X_BinTcp,
                double opening, const std::vector<Eigen::Vector3d>& waypoints) {
  return !ToolClearanceProblem(bin, tool, X_BinTcp, opening, waypoints).has_value();
}

}  // namespace tubepick
