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

}  // namespace tubepick
