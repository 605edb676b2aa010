#pragma once

// AnalyzeWrench's work on checked inputs, shared by the server's handler and the cell controller's
// local fallback (the same analysis when the planner cannot be reached while a tube is held).

#include <Eigen/Geometry>

#include "core/wrench/wrench.h"
#include "core/wrench/wrench_params.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick {

/// One AnalyzeWrench call: readings in the sensor (TCP) axes, the tube mass, the lift pose and the
/// parameters already fitted to that pose (WrenchParamsAtPose).
struct WrenchJob {
  Wrench reference;
  Wrench current;
  double tube_mass = 0.0;
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  WrenchParams params;
};

/// `params` with the vertical taken from the pose: up_Tcp = R_BinTcpᵀ · z_Bin (the sensor axes are
/// the TCP's), and a joint-safe axis fixed in the TCP frame re-projected onto this pose's
/// horizontal plane. @throws InvalidArgument when the TCP z axis is more than params.max_tilt from
/// the vertical or the vertical is parallel to the joint-safe axis (field names as in
/// AnalyzeWrenchRequest).
WrenchParams WrenchParamsAtPose(WrenchParams params, const Eigen::Isometry3d& X_BinTcp);

/// Algorithm 3's count and, for several tubes, the resolution rotation (thesis §4.4).
v1::AnalyzeWrenchResponse RunAnalyzeWrench(const WrenchJob& job);

}  // namespace tubepick
