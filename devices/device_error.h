#pragma once

#include <chrono>
#include <stdexcept>
#include <string>

namespace tubepick::devices {

/// A device did not answer within its timeout.
class DeviceTimeout : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A device answered with a fault or an unexpected reply (the message says which and why).
class DeviceFault : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using Timeout = std::chrono::milliseconds;

}  // namespace tubepick::devices
