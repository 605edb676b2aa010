#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "core/wrench/wrench.h"
#include "devices/device_error.h"

namespace tubepick::devices {

/// One force/torque reading in the sensor frame (axes of the TCP), N and N·m.
struct WrenchReading {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  /// Sensor-side sequence number or time stamp, when the device gives one.
  std::uint64_t sequence = 0;
};

/// The reading as the wrench analysis takes it (core/wrench/wrench.h: the same frame and signs).
inline Wrench AsWrench(const WrenchReading& r) { return Wrench{r.force, r.torque}; }

/// A 6-axis force/torque sensor (thesis §5.3.1.4).
class ForceTorqueSensor {
 public:
  virtual ~ForceTorqueSensor() = default;
  /// The latest reading. @throws DeviceTimeout, DeviceFault.
  virtual WrenchReading Read(Timeout timeout) = 0;
  /// Zeroes the sensor's offsets (tare) at the current load. @throws DeviceTimeout, DeviceFault.
  virtual void Bias(Timeout timeout) = 0;
};

}  // namespace tubepick::devices
