#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "devices/device_error.h"

namespace tubepick::devices {

/// A robot arm moving its tool-centre point (thesis §5.3.1.1). Poses are X_BinTcp: the TCP in the
/// bin frame (the driver owns the transform to the robot base).
class Robot {
 public:
  virtual ~Robot() = default;
  /// Moves the TCP linearly to `X_BinTcp` at `speed` m/s and waits until it arrives.
  /// @throws DeviceTimeout, DeviceFault (robot error, joint limit, servo off).
  virtual void MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Timeout timeout) = 0;
  /// Moves through relative translations of the TCP (bin axes), first (0,0,0), at `speed`.
  /// @throws DeviceTimeout, DeviceFault.
  virtual void MoveThrough(const std::vector<Eigen::Vector3d>& waypoints, double speed, Timeout timeout) = 0;
  /// @throws DeviceTimeout, DeviceFault.
  virtual Eigen::Isometry3d CurrentPose(Timeout timeout) = 0;
  /// Servo power on. @throws DeviceTimeout, DeviceFault.
  virtual void ServoOn(Timeout timeout) = 0;
};

}  // namespace tubepick::devices
