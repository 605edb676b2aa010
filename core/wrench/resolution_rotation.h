#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/wrench/wrench.h"
#include "core/wrench/wrench_params.h"

namespace tubepick {

/// One pose the TCP moves to. Frame `Tcp` is the TCP at lift time (when `current` was read); every
/// step is a pure rotation about the TCP origin (§5.2.6: "the gripper rotates around its tip").
struct ResolutionWaypoint {
  /// Pose of the TCP after this step in the lift-time TCP frame (translation is zero).
  Eigen::Isometry3d X_TcpTcpRotated = Eigen::Isometry3d::Identity();
  /// The same pose in the bin frame: X_BinTcp · X_TcpTcpRotated.
  Eigen::Isometry3d X_BinTcpRotated = Eigen::Isometry3d::Identity();
  /// What this step does, for logs and operators.
  std::string description;
};

/// One resolution motion: the waypoints to execute in order (the last is the final pose).
struct ResolutionMotion {
  /// Unit axis of the tilt in the lift-time TCP frame.
  Eigen::Vector3d axis_Tcp = Eigen::Vector3d::UnitX();
  /// Signed tilt angle about axis_Tcp (right-hand rule), radians.
  double angle = 0.0;
  /// kJointSafe: yaw about up_Tcp before the tilt, radians; 0 for the other variants.
  double yaw = 0.0;
  std::vector<ResolutionWaypoint> waypoints;
  /// The whole motion in one sentence.
  std::string description;
};

/// The planned resolution for one reading.
struct ResolutionPlan {
  /// ΔM = M − M_ref with its vertical component removed (Eq. 5.7 when up_Tcp = ±z), N·m, in Tcp.
  Eigen::Vector3d delta_torque_Tcp = Eigen::Vector3d::Zero();
  /// delta_torque_Tcp normalised: the axis the payload would rotate about if released (Fig. 5.6).
  Eigen::Vector3d torque_axis_Tcp = Eigen::Vector3d::UnitX();
  /// Alternatives to try in order: kPerpendicular gives +angle then −angle,
  /// kTorqueAxisThenPerpendicular the torque axis then the perpendicular, the others one motion.
  std::vector<ResolutionMotion> motions;
};

/// ΔM = M − M_ref with its component along up_Tcp removed (Eq. 5.7: exactly [ΔMx, ΔMy, 0] when
/// up_Tcp = ±z), N·m, in Tcp. up_Tcp is normalised here.
Eigen::Vector3d HorizontalTorqueChange(const Wrench& reference, const Wrench& current,
                                       const Eigen::Vector3d& up_Tcp);

/// Entanglement-resolution rotation (§5.2.6) and its variants (params.variant, see
/// ResolutionVariant). Readings are in the sensor frame, whose axes are the TCP's (wrench.h).
/// @param reference reading with the gripper empty (M_x_ref, M_y_ref).
/// @param current reading after lifting with several tubes held (M_x, M_y).
/// @param X_BinTcp TCP pose at lift time; maps the waypoints to the bin frame, checks that the
///   gripper is vertical (params.up_Tcp within params.max_tilt of the bin's +z) and, for
///   JointSafeFrame::kBin, maps the joint-safe axis into the TCP frame.
/// @return std::nullopt when |ΔM| < params.min_torque: no defined rotation axis.
/// @throws InvalidArgument when a reading is not finite, X_BinTcp is not a finite rigid
///   transform or is tilted beyond params.max_tilt, or params is invalid.
std::optional<ResolutionPlan> PlanResolutionRotation(const Wrench& reference, const Wrench& current,
                                                     const Eigen::Isometry3d& X_BinTcp,
                                                     const WrenchParams& params);

}  // namespace tubepick
