#include "core/wrench/resolution_rotation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {
namespace {

// Yaws closer than this count as a tie (prefer +joint_safe_axis), radians.
constexpr double kYawTieTol = 1e-9;

std::string FormatVector(const Eigen::Vector3d& v) {
  // Round-off below the printed precision must not show up as "-0.000".
  const auto clean = [](double x) { return std::abs(x) < 5e-4 ? 0.0 : x; };
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "[%.3f, %.3f, %.3f]", clean(v.x()), clean(v.y()), clean(v.z()));
  return buffer;
}

std::string FormatDegrees(double radians) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%+.1f deg", radians * 180.0 / M_PI);
  return buffer;
}

Eigen::Matrix3d Rotation(double angle, const Eigen::Vector3d& unit_axis) {
  return Eigen::AngleAxisd(angle, unit_axis).toRotationMatrix();
}

ResolutionWaypoint MakeWaypoint(const Eigen::Matrix3d& R_TcpTcpRotated, const Eigen::Isometry3d& X_BinTcp,
                                std::string description) {
  ResolutionWaypoint waypoint;
  waypoint.X_TcpTcpRotated = Eigen::Isometry3d::Identity();
  waypoint.X_TcpTcpRotated.linear() = R_TcpTcpRotated;
  waypoint.X_BinTcpRotated = X_BinTcp * waypoint.X_TcpTcpRotated;
  waypoint.description = std::move(description);
  return waypoint;
}

// A single rotation about `axis_Tcp` through the TCP.
ResolutionMotion Tilt(const Eigen::Vector3d& axis_Tcp, double angle, const std::string& axis_name,
                      const Eigen::Isometry3d& X_BinTcp) {
  ResolutionMotion motion;
  motion.axis_Tcp = axis_Tcp;
  motion.angle = angle;
  motion.description = "rotate " + FormatDegrees(angle) + " about " + axis_name + " " +
                       FormatVector(axis_Tcp) + " of the lift-time TCP frame, about the TCP";
  motion.waypoints.push_back(MakeWaypoint(Rotation(angle, axis_Tcp), X_BinTcp, motion.description));
  return motion;
}

// Signed angle that turns unit vector `from` onto unit vector `to` about unit `axis` (both ⟂ axis).
double SignedAngle(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& axis) {
  return std::atan2(axis.dot(from.cross(to)), from.dot(to));
}

// The joint-safe axis in the lift-time TCP frame, perpendicular to up (unit).
Eigen::Vector3d JointSafeAxis_Tcp(const WrenchParams& params, const Eigen::Vector3d& up_Tcp,
                                  const Eigen::Isometry3d& X_BinTcp) {
  Eigen::Vector3d axis = params.joint_safe_axis.normalized();
  if (params.joint_safe_frame == JointSafeFrame::kBin) axis = X_BinTcp.linear().transpose() * axis;
  axis -= axis.dot(up_Tcp) * up_Tcp;
  if (axis.norm() < 1e-9) {
    throw InvalidArgument("X_BinTcp: the TCP's vertical is parallel to wrench.joint_safe_axis " +
                          FormatVector(params.joint_safe_axis) + "; the joint-safe yaw is undefined");
  }
  return axis.normalized();
}

ResolutionMotion JointSafe(const Eigen::Vector3d& torque_axis_Tcp, const Eigen::Vector3d& up_Tcp,
                           const WrenchParams& params, const Eigen::Isometry3d& X_BinTcp) {
  const Eigen::Vector3d axis_Tcp = JointSafeAxis_Tcp(params, up_Tcp, X_BinTcp);
  // Yaw ψ about the vertical through the TCP turns the gripper and its payload, so ΔM (fixed in the
  // gripper) turns too: afterwards it points along R(ψ, up)·m in the lift-time frame. Pick ψ so
  // that this is s·axis, s = ±1.
  double sign = 1.0;
  double yaw = SignedAngle(torque_axis_Tcp, axis_Tcp, up_Tcp);
  if (params.joint_safe_min_yaw) {
    const double yaw_negative = SignedAngle(torque_axis_Tcp, -axis_Tcp, up_Tcp);
    if (std::abs(yaw_negative) + kYawTieTol < std::abs(yaw)) {
      sign = -1.0;
      yaw = yaw_negative;
    }
  }
  // +angle about ΔM = +angle about s·axis = s·angle about axis; the lift-time axis is fixed in
  // space, so this rotation composes on the left: R = R(s·angle, axis) · R(ψ, up)
  // (= R(ψ, up) · R(angle, m): the tilt relative to the payload is kTorqueAxis's).
  const double angle = sign * params.rotation_angle;
  const Eigen::Matrix3d R_TcpTcpYawed = Rotation(yaw, up_Tcp);
  const Eigen::Matrix3d R_TcpTcpRotated = Rotation(angle, axis_Tcp) * R_TcpTcpYawed;

  const std::string axis_name = std::string(sign > 0.0 ? "+" : "-") + "joint-safe axis";
  const std::string yaw_text = "yaw " + FormatDegrees(yaw) + " about the TCP vertical " +
                               FormatVector(up_Tcp) + " so the torque axis lines up with the " + axis_name +
                               " " + FormatVector(sign * axis_Tcp);
  const std::string tilt_text = "rotate " + FormatDegrees(angle) + " about the joint-safe axis " +
                                FormatVector(axis_Tcp) + " of the lift-time TCP frame, about the TCP";

  ResolutionMotion motion;
  motion.axis_Tcp = axis_Tcp;
  motion.angle = angle;
  motion.yaw = yaw;
  motion.waypoints.push_back(MakeWaypoint(R_TcpTcpYawed, X_BinTcp, yaw_text));
  motion.waypoints.push_back(MakeWaypoint(R_TcpTcpRotated, X_BinTcp, tilt_text));
  motion.description = yaw_text + ", then " + tilt_text;
  return motion;
}

}  // namespace

Eigen::Vector3d HorizontalTorqueChange(const Wrench& reference, const Wrench& current,
                                       const Eigen::Vector3d& up_Tcp) {
  const Eigen::Vector3d up = up_Tcp.normalized();
  const Eigen::Vector3d delta = current.torque - reference.torque;
  return delta - delta.dot(up) * up;
}

std::optional<ResolutionPlan> PlanResolutionRotation(const Wrench& reference, const Wrench& current,
                                                     const Eigen::Isometry3d& X_BinTcp,
                                                     const WrenchParams& params) {
  params.Validate();
  RequireFiniteVector(reference.torque, "reference.torque");
  RequireFiniteVector(current.torque, "current.torque");
  RequireRigid(X_BinTcp, "X_BinTcp");

  const Eigen::Vector3d up_Tcp = params.up_Tcp.normalized();
  const Eigen::Vector3d up_Bin = X_BinTcp.linear() * up_Tcp;
  const double tilt = std::acos(std::clamp(up_Bin.z(), -1.0, 1.0));
  if (tilt > params.max_tilt) {
    throw InvalidArgument("X_BinTcp: wrench.up_Tcp " + FormatVector(params.up_Tcp) + " points " +
                          FormatVector(up_Bin) + " in the bin frame, " + FormatDegrees(tilt) +
                          " from the bin's +z (wrench.max_tilt " + FormatDegrees(params.max_tilt) +
                          "): the gripper must be vertical at lift, or wrench.up_Tcp is wrong");
  }

  ResolutionPlan plan;
  plan.delta_torque_Tcp = HorizontalTorqueChange(reference, current, up_Tcp);
  const double magnitude = plan.delta_torque_Tcp.norm();
  if (!(magnitude >= params.min_torque)) return std::nullopt;
  plan.torque_axis_Tcp = plan.delta_torque_Tcp / magnitude;

  const double angle = params.rotation_angle;
  const Eigen::Vector3d perpendicular_Tcp = up_Tcp.cross(plan.torque_axis_Tcp).normalized();
  constexpr const char* kPerpendicularName = "the horizontal axis perpendicular to the torque";
  switch (params.variant) {
    case ResolutionVariant::kTorqueAxis:
      plan.motions.push_back(Tilt(plan.torque_axis_Tcp, angle, "the torque axis", X_BinTcp));
      break;
    case ResolutionVariant::kTorqueAxisNegative:
      plan.motions.push_back(Tilt(plan.torque_axis_Tcp, -angle, "the torque axis", X_BinTcp));
      break;
    case ResolutionVariant::kPerpendicular:
      plan.motions.push_back(Tilt(perpendicular_Tcp, angle, kPerpendicularName, X_BinTcp));
      plan.motions.push_back(Tilt(perpendicular_Tcp, -angle, kPerpendicularName, X_BinTcp));
      break;
    case ResolutionVariant::kTorqueAxisThenPerpendicular:
      plan.motions.push_back(Tilt(plan.torque_axis_Tcp, angle, "the torque axis", X_BinTcp));
      plan.motions.push_back(Tilt(perpendicular_Tcp, angle, kPerpendicularName, X_BinTcp));
      break;
    case ResolutionVariant::kJointSafe:
      plan.motions.push_back(JointSafe(plan.torque_axis_Tcp, up_Tcp, params, X_BinTcp));
      break;
  }
  return plan;
}

}  // namespace tubepick
