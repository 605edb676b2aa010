#pragma once

#include <Eigen/Geometry>

#include "core/wrench/wrench.h"

namespace tubepick {

/// Where a payload of several tubes is held while the resolution rotation shakes it.
struct ResolutionHold {
  /// The payload's centre of mass relative to the TCP, horizontal, bin frame, metres:
  /// r = (ΔM_y, −ΔM_x) / W with ΔM the torque change and W the weight gained, both in the bin's
  /// axes (a load W at r below the sensor reads ΔM = r × (0, 0, −W)). Zero when W ≤ 0.
  Eigen::Vector3d p_TcpPayload_Bin = Eigen::Vector3d::Zero();
  /// Translation (bin frame, z = 0) from the lift pose to the hold pose: the payload's centre of
  /// mass over the bin floor's centre, the TCP kept at least `wall_margin` inside the inner walls
  /// (clamped per axis; at the centre when the bin is narrower than two margins).
  Eigen::Vector3d shift_Bin = Eigen::Vector3d::Zero();
};

/// The hold pose of a resolution: tubes the rotation frees fall from the payload's side, so the
/// payload is brought over the middle of the bin first (the thesis kept to 45° for fear of throwing
/// tubes out of the bin, §5.3.4). `reference` is the empty gripper's reading, `lifted` the one at
/// X_BinTcpLift (sensor axes = TCP axes, wrench.h); `bin_inner_size` the bin's inner length,
/// width and height (the bin frame's origin is the floor's centre).
/// @throws InvalidArgument when a reading or the pose is not finite, or wall_margin < 0.
ResolutionHold PlanResolutionHold(const Wrench& reference, const Wrench& lifted,
                                  const Eigen::Isometry3d& X_BinTcpLift,
                                  const Eigen::Vector3d& bin_inner_size, double wall_margin);

/// What hangs on the tool, from a reading `now` against the empty gripper's `reference` (sensor
/// axes = TCP axes) with the TCP at orientation R_BinTcp.
struct Payload {
  /// Newtons; negative when the tool is pushed up (pressing on something).
  double weight = 0.0;
  /// The payload's centre of mass relative to the TCP, horizontal, bin frame (as
  /// ResolutionHold::p_TcpPayload_Bin); zero when weight ≤ 0.
  Eigen::Vector3d p_TcpPayload_Bin = Eigen::Vector3d::Zero();
};
/// @throws InvalidArgument when a reading is not finite or R_BinTcp is not a rotation.
Payload PayloadOnTool(const Wrench& reference, const Wrench& now, const Eigen::Matrix3d& R_BinTcp);

/// Whether `payload` can be tubes hanging from the tool: its centre of mass within `tube_length`
/// (the cell's tube.length; 0 = unknown: any) of the TCP. Farther, something else pulls on it (a
/// tube caught on the heap or a wall), and its torque says nothing of where the payload would lie.
bool HangsFromTheTool(const Payload& payload, double tube_length);

/// Translation (bin frame, z = 0) that brings a payload's centre of mass, hanging at
/// p_TcpPayload_Bin from a TCP at p_Bin_tcp, at least `margin` inside the bin's inner walls, and no
/// further: per axis, zero where it already is, to the bin's middle where the bin is narrower than
/// two margins. The TCP never moves further out than it was or than `margin` inside the walls, per
/// axis, whatever the centre of mass: a reading far past a wall is no free-hanging load. Where
/// several tubes the resolution could not free are put back: lowered where they hang, they lie down
/// where they came from, but a centre of mass at a wall lays them over it.
/// @throws InvalidArgument when a vector is not finite or margin < 0 (named put_back_margin).
Eigen::Vector3d PlanPutBackShift(const Eigen::Vector3d& p_Bin_tcp, const Eigen::Vector3d& p_TcpPayload_Bin,
                                 const Eigen::Vector3d& bin_inner_size, double margin);

}  // namespace tubepick
