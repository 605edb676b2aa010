#pragma once

#include <utility>

#include <Eigen/Geometry>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "devices/device_error.h"

namespace tubepick::devices {

/// One capture: the cloud as the scanner gives it, and where the scanner was.
struct Capture {
  /// Sensor optical frame, in `unit`.
  Points points_Sensor;
  LengthUnit unit = LengthUnit::kMetre;
  /// X_BinSensor at capture time.
  Eigen::Isometry3d X_BinSensor = SensorConfig::DefaultX_BinSensor();
};

/// A capture of `points_Sensor` by a sensor mounted and calibrated as `sensor` says.
inline Capture CaptureOf(Points points_Sensor, const SensorConfig& sensor) {
  Capture capture;
  capture.points_Sensor = std::move(points_Sensor);
  capture.unit = sensor.unit;
  capture.X_BinSensor = sensor.X_BinSensor;
  return capture;
}

/// A 3-D scanner (thesis §5.3.1.3).
class Scanner {
 public:
  virtual ~Scanner() = default;
  /// @throws DeviceTimeout, DeviceFault.
  virtual devices::Capture Scan(Timeout timeout) = 0;
};

}  // namespace tubepick::devices
