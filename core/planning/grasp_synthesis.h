#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/types.h"

namespace tubepick {

/// Grasp synthesis (thesis §5.2.4.1, Table 5.3).
struct GraspParams {
  /// Distance between consecutive grasp points along a cylinder axis, metres.
  double spacing = 0.02;
  /// Minimum distance between a grasp point and its cylinder's bases, metres (Table 5.3: 2 cm).
  double min_base_distance = 0.02;
  /// Distance between the open fingers' inner faces at the pre-grasp pose, metres; must exceed
  /// the tube diameter (Robotiq 2F-85 stroke: up to 0.085).
  double opening_width = 0.045;
  /// Cylinders whose axis rises more than this above the horizontal get no grasps (a vertical
  /// gripper cannot close across a steep cylinder), radians. Beyond the thesis.
  double max_axis_inclination = 1.0471975511965976;  // 60°
  /// Beyond the thesis: a grasp whose tool would touch a wall on the vertical approach is tried
  /// again with the tool turned about the tube (x_Tcp), its top leaning away from the wall, by
  /// tilt_step, 2·tilt_step, ... up to max_tilt, radians (0 = vertical approaches only). A tube
  /// lying along a wall a few centimetres from it leaves no room for the housing of a vertical
  /// tool (0.068 m from the axis with the 2F-85): in a simulated 20-tree bin (seed 12) the last
  /// tree lay 3.9 cm from the +y wall and every grasp of it was refused.
  double max_tilt = 0.5235987755982988;   // 30°
  double tilt_step = 0.2617993877991494;  // 15°
};

/// A grasp of a virtual tube (Def. 5.2.7), bin frame.
struct Grasp {
  /// Pose of the TCP at grasp time: origin at the grasp point, z_Tcp along the approach (down,
  /// −z_Bin), y_Tcp the fingers' closing direction (horizontal, ⟂ the cylinder axis), x_Tcp along
  /// the cylinder axis' xy projection, signed so that x_Tcp·x_Bin > 0 (or x_Tcp·y_Bin > 0 when
  /// the axis is parallel to y_Bin): the yaw is in (−90°, 90°].
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  /// Unit approach direction, z_Tcp: −z_Bin, or tilted by `tilt` about x_Tcp.
  Eigen::Vector3d approach_Bin{0.0, 0.0, -1.0};
  /// The tool's turn about x_Tcp away from the vertical approach, radians (0: vertical).
  double tilt = 0.0;
  /// Finger opening at the pre-grasp pose, metres.
  double opening_width = 0.0;
  /// The grasp point G on the cylinder axis (== X_BinTcp.translation()).
  Eigen::Vector3d p_Bin_grasp = Eigen::Vector3d::Zero();
  /// Which cylinder of the tube holds the grasp point.
  std::uint32_t cylinder_index = 0;
  /// Distance of the grasp point along its branch's curve (cylinders and joints, as
  /// Tube::length()) from the branch's from_node; on a linear tube from cylinders.front().start,
  /// metres.
  double curve_position = 0.0;
};

/// TCP pose for a grasp at `p_Bin_grasp` on a cylinder with axis `axis_Bin` (see Grasp::X_BinTcp).
/// nullopt when the axis has no xy component (|xy| < 1e-9 of its norm).
std::optional<Eigen::Isometry3d> GraspFrame(const Eigen::Vector3d& p_Bin_grasp,
                                            const Eigen::Vector3d& axis_Bin);

/// `vertical` turned by `tilt` radians about its x_Tcp (the tube's direction), the TCP staying on
/// the grasp point: X_BinTcp · R_x(tilt); the approach follows the new z_Tcp.
Grasp TiltedGrasp(const Grasp& vertical, double tilt);

/// The tilts a grasp the vertical tool cannot reach is tried with, smallest first, each turn
/// both ways: +step, −step, +2·step, −2·step, ... while |tilt| ≤ max_tilt (none when max_tilt is 0).
std::vector<double> GraspTilts(const GraspParams& params);

/// Curve positions of each cylinder's start along its branch from the branch's from_node
/// (cylinder lengths plus joint lengths; a linear tube's one branch starts at its first cylinder).
std::vector<double> CylinderCurveOffsets(const Tube& tube);

/// Grasp points along each cylinder's axis: on a cylinder of length ℓ, the usable stretch is
/// [m, ℓ − m] (m = min_base_distance); it holds n = ⌊(ℓ − 2m)/spacing⌋ + 1 points `spacing`
/// apart, centred in the stretch (none when ℓ < 2m). Cylinders steeper than
/// max_axis_inclination are skipped. Order: cylinder, then along the cylinder.
/// @pre params validated.
std::vector<Grasp> SynthesizeGrasps(const Tube& tube, const GraspParams& params);

}  // namespace tubepick
