#include "wire/wrench_analysis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "core/common/errors.h"
#include "core/wrench/held_count.h"
#include "core/wrench/resolution_rotation.h"
#include "wire/response_convert.h"

namespace tubepick {
namespace {

std::string Degrees(double radians) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.1f deg", radians * 180.0 / M_PI);
  return buffer;
}

}  // namespace

WrenchParams WrenchParamsAtPose(WrenchParams params, const Eigen::Isometry3d& X_BinTcp) {
  // The sensor axes are the TCP's (wrench.h), so the upward direction in the sensor frame is
  // up_Tcp = R_BinTcpᵀ · z_Bin. Our grasp TCPs point z down (approach), which gives (0, 0, −1);
  // a thesis-style sensor with z up gives (0, 0, 1). F_z of Algorithm 3 is then force · up_Tcp.
  const Eigen::Matrix3d R_BinTcp = X_BinTcp.linear();
  params.up_Tcp = R_BinTcp.transpose() * Eigen::Vector3d::UnitZ();
  // With up_Tcp taken from the pose, the resolution planner's tilt guard always passes; keep its
  // intent here: the tool axis (TCP z, up or down) must be within wrench.max_tilt of the vertical.
  const double tilt = std::acos(std::clamp(std::abs(R_BinTcp(2, 2)), 0.0, 1.0));
  if (tilt > params.max_tilt) {
    throw InvalidArgument("tcp_pose.orientation: the TCP z axis is " + Degrees(tilt) +
                          " from the vertical (wrench.max_tilt " + Degrees(params.max_tilt) +
                          "); the gripper must be vertical at lift, or tilted no more than a grasp is");
  }
  // A joint-safe axis fixed in the TCP frame is horizontal for the configured up_Tcp; re-project it
  // onto the horizontal plane of this pose (it differs by at most max_tilt).
  if (params.joint_safe_frame == JointSafeFrame::kTcp) {
    const Eigen::Vector3d up = params.up_Tcp;
    Eigen::Vector3d axis = params.joint_safe_axis.normalized();
    axis -= axis.dot(up) * up;
    if (axis.norm() < 1e-6) {
      throw InvalidArgument("tcp_pose.orientation: the vertical is parallel to wrench.joint_safe_axis");
    }
    params.joint_safe_axis = axis.normalized();
  }
  return params;
}

v1::AnalyzeWrenchResponse RunAnalyzeWrench(const WrenchJob& job) {
  const HeldCount count = CountHeldTubes(job.reference, job.current, job.tube_mass, job.params);
  std::optional<ResolutionPlan> resolution;
  Eigen::Vector3d delta_torque_Tcp = Eigen::Vector3d::Zero();
  if (count.outcome == HeldOutcome::kMultiple) {
    delta_torque_Tcp = HorizontalTorqueChange(job.reference, job.current, job.params.up_Tcp);
    resolution = PlanResolutionRotation(job.reference, job.current, job.X_BinTcp, job.params);
  }
  return ToAnalyzeWrenchResponse(count, resolution, delta_torque_Tcp);
}

}  // namespace tubepick
