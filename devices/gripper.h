#pragma once

#include <cstdint>
#include <string>

#include "devices/device_error.h"

namespace tubepick::devices {

/// What the gripper reports after a motion (Robotiq gOBJ semantics).
enum class GripperObject {
  kMoving,          ///< still moving, no object detected
  kStoppedOpening,  ///< contact while opening
  kStoppedClosing,  ///< contact while closing: an object is held
  kAtPosition,      ///< reached the requested position: no object
};

struct GripperStatus {
  bool activated = false;
  GripperObject object = GripperObject::kAtPosition;
  /// Finger opening, metres (0 = closed).
  double opening = 0.0;
  /// Fault code (0 = none) and its description.
  std::uint8_t fault = 0;
  std::string fault_text;
};

/// A parallel-jaw gripper (thesis §5.3.1.2, Robotiq 2F-85).
class Gripper {
 public:
  virtual ~Gripper() = default;
  /// Activates (calibrates) the gripper; needed once after power-up. @throws DeviceTimeout, DeviceFault.
  virtual void Activate(Timeout timeout) = 0;
  /// Moves the fingers to `opening` metres at `speed` m/s with `force` N and waits for the motion
  /// to end. @throws DeviceTimeout, DeviceFault (fault reported by the gripper).
  virtual GripperStatus MoveTo(double opening, double speed, double force, Timeout timeout) = 0;
  /// Fully open. @throws DeviceTimeout, DeviceFault.
  virtual GripperStatus Open(Timeout timeout) = 0;
  /// Closes until contact or fully closed. @throws DeviceTimeout, DeviceFault.
  virtual GripperStatus Close(double speed, double force, Timeout timeout) = 0;
  /// The current status; a gripper fault is reported in GripperStatus::fault (not thrown), so a
  /// caller can inspect it. @throws DeviceTimeout, or DeviceFault when the link itself fails.
  virtual GripperStatus Status(Timeout timeout) = 0;
};

}  // namespace tubepick::devices
