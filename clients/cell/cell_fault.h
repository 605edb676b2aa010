#pragma once

#include <stdexcept>
#include <string>

namespace tubepick::cell {

/// Why the cell stopped in a fault (thesis §5.1's skills report failure; here every failure has a
/// device and a kind so that an operator knows where to look).
enum class FaultKind {
  /// A device did not answer within its timeout (devices::DeviceTimeout).
  kTimeout,
  /// A device answered with a fault (devices::DeviceFault, a gripper fault status, a robot error).
  kDeviceFault,
  /// The planner could not be reached or kept failing (UNAVAILABLE / RESOURCE_EXHAUSTED after the
  /// retries, DEADLINE_EXCEEDED).
  kServerUnavailable,
  /// The planner rejected the request or gave an unusable answer.
  kServerError,
  /// The F/T sensor weighs a load where the tool should carry nothing (a tube caught on the pads
  /// or the housing after a failed grasp, a put-back or a nudge).
  kUnexpectedLoad,
  /// Anything else (a bug): still ends in a safe stop.
  kInternal,
};

/// "timeout", "device_fault", "server_unavailable", "server_error", "unexpected_load", "internal".
std::string ToString(FaultKind kind);

/// A fault the controller cannot recover from. `device` is "scanner", "robot", "gripper",
/// "ft_sensor", "planner" or "controller"; `state` the controller state it happened in.
class CellFault : public std::runtime_error {
 public:
  CellFault(std::string device, FaultKind kind, std::string state, std::string error);
  const std::string& device() const { return device_; }
  FaultKind kind() const { return kind_; }
  const std::string& state() const { return state_; }
  /// The device's / planner's own message.
  const std::string& error() const { return error_; }

 private:
  std::string device_;
  FaultKind kind_;
  std::string state_;
  std::string error_;
};

}  // namespace tubepick::cell
