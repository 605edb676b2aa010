#pragma once

#include <cstdint>
#include <string>

#include "devices/device_error.h"

namespace tubepick::devices {

/// The active configuration of an ATI Net F/T as its web server gives it (netftapi2.xml):
/// counts per force and torque unit, and those units.
struct NetFtCalibration {
  double counts_per_force = 0.0;   ///< cfgcpf, counts per `force_unit`
  double counts_per_torque = 0.0;  ///< cfgcpt, counts per `torque_unit`
  std::string force_unit;          ///< scfgfu: "N", "kN", "lbf", "klbf", "g", "kg"
  std::string torque_unit;         ///< scfgtu: "Nm" ("N-m"), "N-mm", "kN-m", "lbf-in", "lbf-ft"
  /// Counts per N and per N·m, the driver's units (AtiNetFtParams).
  /// @throws InvalidArgument naming a unit it does not know.
  double CountsPerNewton() const;
  double CountsPerNewtonMetre() const;
};

/// Reads cfgcpf, cfgcpt, scfgfu, scfgtu from netftapi2.xml text.
/// @throws DeviceFault naming the missing or malformed element.
NetFtCalibration ParseNetFtApi2(const std::string& xml);

/// GET http://host:port/netftapi2.xml (HTTP/1.0) and ParseNetFtApi2.
/// @throws DeviceTimeout (no connection or answer within `timeout`), DeviceFault (refused, not
///         200, malformed).
NetFtCalibration ReadNetFtCalibration(const std::string& host, std::uint16_t port, Timeout timeout);

}  // namespace tubepick::devices
