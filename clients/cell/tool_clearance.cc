#include "clients/cell/tool_clearance.h"

#include <fmt/core.h>

#include <array>
#include <cmath>

namespace tubepick::cell {
namespace {

struct Box {
  const char* name;
  Eigen::Vector3d centre_Tcp;
  Eigen::Vector3d half_size;
};

}  // namespace

std::optional<std::string> ToolClearanceProblem(const CellConfig& cell, const ToolGeometry& tool,
                                                const Eigen::Isometry3d& X_BinTcp_grasp, double opening,
                                                const std::vector<Eigen::Vector3d>& waypoints) {
  const double finger_z = tool.finger_tip_depth - 0.5 * tool.finger_size.z();
  const double finger_y = 0.5 * (opening + tool.finger_size.y());
  const double housing_z =
      tool.finger_tip_depth - tool.finger_size.z() - tool.housing_gap - 0.5 * tool.housing_size.z();
  const std::array<Box, 3> boxes = {
      Box{"finger", Eigen::Vector3d(0.0, finger_y, finger_z), 0.5 * tool.finger_size},
      Box{"finger", Eigen::Vector3d(0.0, -finger_y, finger_z), 0.5 * tool.finger_size},
      Box{"housing", Eigen::Vector3d(0.0, 0.0, housing_z), 0.5 * tool.housing_size}};
  const Eigen::Vector3d half_bin = 0.5 * cell.bin.inner_size;
  const double wall_top = cell.bin.inner_size.z();
  const std::vector<Eigen::Vector3d> path =
      waypoints.empty() ? std::vector<Eigen::Vector3d>{Eigen::Vector3d::Zero()} : waypoints;
  for (std::size_t w = 0; w < path.size(); ++w) {
    Eigen::Isometry3d X = X_BinTcp_grasp;
    X.translation() += path[w];
    for (const Box& box : boxes) {
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d offset((corner & 1 ? 1 : -1) * box.half_size.x(),
                                     (corner & 2 ? 1 : -1) * box.half_size.y(),
                                     (corner & 4 ? 1 : -1) * box.half_size.z());
        const Eigen::Vector3d p = X * (box.centre_Tcp + offset);
        if (p.z() >= wall_top) continue;
        const double past_x = std::abs(p.x()) - (half_bin.x() - tool.margin);
        const double past_y = std::abs(p.y()) - (half_bin.y() - tool.margin);
        if (past_x > 0.0 || past_y > 0.0) {
          const bool x_wall = past_x >= past_y;
          return fmt::format(
              "{} {:.3f} m into the {}{} wall at waypoint {} (point ({:.3f}, {:.3f}, {:.3f}) m)", box.name,
              x_wall ? past_x : past_y, (x_wall ? p.x() : p.y()) > 0 ? "+" : "-", x_wall ? "x" : "y", w,
              p.x(), p.y(), p.z());
        }
        if (p.z() < tool.margin)
          return fmt::format("{} {:.3f} m below the floor at waypoint {} (point ({:.3f}, {:.3f}, {:.3f}) m)",
                             box.name, tool.margin - p.z(), w, p.x(), p.y(), p.z());
      }
    }
  }
  return std::nullopt;
}

}  // namespace tubepick::cell
