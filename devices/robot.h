#pragma once

#include <cmath>
#include <optional>
#include <vector>

#include <string>

#include <Eigen/Geometry>

#include "devices/device_error.h"

namespace tubepick::devices {

/// What the arm can reach and how fast, so a caller can check a plan before moving (a target beyond
/// the limits is a DeviceFault from the robot itself, often after the arm already moved).
struct RobotLimits {
  /// Highest TCP speed, m/s; faster requests are clamped.
  double max_speed = 0.25;
  /// Reachable TCP positions, bin frame.
  Eigen::AlignedBox3d reach_Bin{Eigen::Vector3d(-1.5, -1.5, -0.1), Eigen::Vector3d(1.5, 1.5, 1.5)};
  /// Wrist joint limit as seen at the TCP: the largest angle between z_Tcp and straight down (−z_Bin)
  /// the arm reaches, radians.
  double max_tilt = M_PI / 3.0;

  /// Why X_BinTcp is out of reach (position or tilt), or an empty string when it is reachable.
  std::string Problem(const Eigen::Isometry3d& X_BinTcp) const;
};

/// What a robot controller says about itself (devices check, logs).
struct RobotStatus {
  bool servo_on = false;
  bool alarm = false;
  bool error = false;
  /// A motion is under way.
  bool running = false;
  /// The raw status as the controller gives it (e.g. "data 1 0x00000002, data 2 0x00000040").
  std::string detail;
};

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
  /// Keeps the TCP where it is for `seconds` while what hangs from the tool swings and slides (a
  /// resolution rotation's pause at its tilt). A real arm holds its pose with its servos on, so the
  /// default waits on the wall clock; a simulated arm advances its simulation instead.
  /// @throws DeviceFault when `seconds` is negative or not finite; DeviceTimeout when it exceeds
  /// `timeout` (after holding `timeout`). Drivers implement HoldFor.
  void Hold(double seconds, Timeout timeout);
  /// @throws DeviceTimeout, DeviceFault.
  virtual Eigen::Isometry3d CurrentPose(Timeout timeout) = 0;
  /// Servo power on. @throws DeviceTimeout, DeviceFault.
  virtual void ServoOn(Timeout timeout) = 0;
  /// Servo, alarm and motion state, or nullopt when the driver cannot read them.
  /// @throws DeviceTimeout, DeviceFault.
  virtual std::optional<RobotStatus> Status(Timeout /*timeout*/) { return std::nullopt; }
  /// Reach, tilt and speed limits (from the driver's configuration; no device round trip).
  virtual RobotLimits Limits() const = 0;

 protected:
  /// Holds still for `seconds` (finite, >= 0, within the call's timeout: Hold checked them).
  virtual void HoldFor(double seconds);
};

}  // namespace tubepick::devices
