#include <fmt/core.h>

#include <algorithm>

#include "devices/robot.h"

namespace tubepick::devices {

std::string RobotLimits::Problem(const Eigen::Isometry3d& X_BinTcp) const {
  const Eigen::Vector3d p = X_BinTcp.translation();
  if (!p.allFinite() || !X_BinTcp.linear().allFinite()) return "pose is not finite";
  if (!reach_Bin.contains(p)) {
    return fmt::format(
        "TCP ({:.3f}, {:.3f}, {:.3f}) m is out of reach (x [{:.2f}, {:.2f}], y [{:.2f}, {:.2f}], z [{:.2f}, "
        "{:.2f}] m)",
        p.x(), p.y(), p.z(), reach_Bin.min().x(), reach_Bin.max().x(), reach_Bin.min().y(),
        reach_Bin.max().y(), reach_Bin.min().z(), reach_Bin.max().z());
  }
  const double cos_tilt = std::clamp(-X_BinTcp.linear().col(2).normalized().z(), -1.0, 1.0);
  const double tilt = std::acos(cos_tilt);
  if (tilt > max_tilt + 1e-9)
    return fmt::format("tilt {:.1f}° beyond the wrist limit {:.1f}°", tilt * 180.0 / M_PI,
                       max_tilt * 180.0 / M_PI);
  return {};
}

}  // namespace tubepick::devices
