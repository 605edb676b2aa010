#pragma once

#include <string>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "devices/force_torque_sensor.h"
#include "tubepick/v1/planning.pb.h"
#include "tubepick/v1/requests.pb.h"
#include "tubepick/v1/types.pb.h"
#include "tubepick/v1/wrench.pb.h"

namespace tubepick::cell {

/// Client-side conversions between device / core values and the wire messages (tubepick.v1). The
/// client links only the proto stubs, not server/, so it carries its own small set.

v1::Vector3 ToWire(const Eigen::Vector3d& v);
Eigen::Vector3d FromWire(const v1::Vector3& v);
v1::Pose ToWire(const Eigen::Isometry3d& X);
/// The rigid transform of a wire pose; the quaternion is normalised.
/// @throws InvalidArgument naming `field` when it is not finite or has (near) zero norm.
Eigen::Isometry3d FromWire(const v1::Pose& pose, const std::string& field);
v1::Wrench ToWire(const devices::WrenchReading& reading);
v1::LengthUnit ToWire(LengthUnit unit);

/// The CellDescription of `cell` with the sensor pose of the capture (X_BinSensor).
v1::CellDescription ToCellDescription(const CellConfig& cell, const Eigen::Isometry3d& X_BinSensor);

/// "upward", "escape", "occlusion_escape", "unspecified".
std::string TrajectoryKindName(v1::TrajectoryKind kind);
/// "none", "single", "multiple", "unspecified".
std::string HeldOutcomeName(v1::HeldOutcome outcome);

}  // namespace tubepick::cell
