#pragma once

#include <cmath>
#include <string>

#include <Eigen/Core>

namespace tubepick {

/// Which entanglement-resolution rotation to plan (thesis §5.2.6, §5.3.4, §5.4.2).
enum class ResolutionVariant {
  /// The thesis: rotate +angle about the torque vector ΔM (§5.2.6).
  kTorqueAxis,
  /// Rotate −angle about ΔM (proposed after Table 5.8).
  kTorqueAxisNegative,
  /// Two alternatives, +angle then −angle, about the horizontal axis perpendicular to ΔM
  /// (proposed after Table 5.8).
  kPerpendicular,
  /// §5.4.2: first yaw about the TCP's vertical axis so that ΔM lines up with a configured axis,
  /// then rotate about that axis. The tilt relative to the payload equals kTorqueAxis's.
  kJointSafe,
  /// kTorqueAxis, and when several tubes still hang, +angle about the horizontal axis
  /// perpendicular to ΔM (kPerpendicular's first motion; not its second, −angle, which threw six
  /// trees out of a bin in one of 33 simulated double picks). On 33 double picks of pvc set-C
  /// trees it freed 23 against kTorqueAxis's 19, with no tube outside the bin (docs/ACCURACY.md).
  /// A caller that reads the F/T between motions can plan the second from that reading instead
  /// (its first motion: the torque axis the tangle shows then), as the cell controller does with
  /// resolution_replan.
  kTorqueAxisThenPerpendicular,
};

/// Frame in which `WrenchParams::joint_safe_axis` is fixed.
enum class JointSafeFrame {
  /// The TCP frame at lift time (before any resolution motion).
  kTcp,
  /// The bin frame (fixed relative to the robot base: the same wrist motion on every pick).
  kBin,
};

/// Parameters of entanglement detection (Algorithm 3) and resolution (§5.2.6). Frames and signs
/// are described in wrench.h.
struct WrenchParams {
  /// Gravitational acceleration, m/s².
  double gravity = 9.81;
  /// F_tol of Algorithm 3, newtons: half-width of the "single tube" band around the expected
  /// force. Must be below one tube's weight, else an empty gripper reads as holding one tube.
  double force_tolerance = 0.25;
  /// Beyond the thesis: when > 0, the band's half-width is at most this share of one tube's weight
  /// (EffectiveForceTolerance). Algorithm 3's fixed F_tol is 0.46 of a 55 g PVC tube's weight, wide
  /// enough to read a tube with half another hanging from it as one; in [0, 1), 0 = F_tol alone.
  double force_tolerance_share = 0.0;
  /// The upward vertical at lift time, in the TCP (= sensor-axes) frame; the gripper is vertical
  /// at lift (§5.2.4.1). The thesis's sensor has +z up; a TCP whose z is the approach direction
  /// (pointing down) uses (0, 0, -1). Normalised before use.
  Eigen::Vector3d up_Tcp = Eigen::Vector3d::UnitZ();
  /// Largest angle between up_Tcp (mapped to the bin by X_BinTcp) and the bin's +z accepted by the
  /// resolution planner, radians; guards against a wrong up_Tcp or a gripper tilted more than a
  /// grasp ever is (AnalyzeWrench: the TCP z axis from the vertical). At least
  /// planning.grasps.max_tilt (30°): a grasp tilted away from a wall is lifted and analysed so.
  double max_tilt = 35.0 * M_PI / 180.0;
  /// Resolution rotation angle, radians, in (0, π] (Table 5.3: 45°).
  double rotation_angle = M_PI / 4.0;
  /// Smallest |ΔM| (horizontal part) that defines a rotation axis, newton-metres; below it there
  /// is no axis (the ATI Gamma resolves ~7.5e-4 N·m).
  double min_torque = 0.005;
  /// Which rotation to plan.
  ResolutionVariant variant = ResolutionVariant::kTorqueAxis;
  /// kJointSafe: the axis ΔM is yawed onto, about which the robot tilts comfortably; must be
  /// perpendicular to the vertical of its frame (up_Tcp for kTcp, bin +z for kBin).
  Eigen::Vector3d joint_safe_axis = Eigen::Vector3d::UnitX();
  /// kJointSafe: frame of joint_safe_axis.
  JointSafeFrame joint_safe_frame = JointSafeFrame::kTcp;
  /// kJointSafe: align ΔM with +joint_safe_axis or −joint_safe_axis, whichever needs the smaller
  /// yaw (|yaw| ≤ 90°), and tilt with the matching sign; false always aligns with +axis.
  bool joint_safe_min_yaw = true;

  /// @throws InvalidArgument naming the first bad field ("wrench.force_tolerance: ...") and its
  /// value.
  void Validate() const;
};

/// The half-width of Algorithm 3's single band for a tube of `tube_weight` newtons:
/// force_tolerance, or force_tolerance_share · tube_weight when that share is set and smaller.
double EffectiveForceTolerance(const WrenchParams& params, double tube_weight);

/// "torque_axis", "torque_axis_negative", "perpendicular", "joint_safe",
/// "torque_axis_then_perpendicular".
std::string ToString(ResolutionVariant variant);
/// @throws InvalidArgument naming `field` for an unknown name.
ResolutionVariant ParseResolutionVariant(const std::string& text, const std::string& field);
/// "tcp", "bin".
std::string ToString(JointSafeFrame frame);
/// @throws InvalidArgument naming `field` for an unknown name.
JointSafeFrame ParseJointSafeFrame(const std::string& text, const std::string& field);

}  // namespace tubepick
