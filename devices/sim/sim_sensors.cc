// The simulated scanner (the virtual scanner on the current tube poses) and F/T sensor.

#include <fmt/format.h>

#include "core/common/types.h"
#include "devices/sim/sim_devices.h"
#include "physics/seeds.h"
#include "physics/virtual_scanner.h"

namespace tubepick::devices::sim {
namespace {

/// Sub-stream of the cell seed for scan number k (streams 1..3 are the tubes, drop and F/T noise).
constexpr std::uint64_t kScanStream = 1000;

}  // namespace

devices::Capture SimScanner::Scan(Timeout timeout) {
  state_.ThrowIfInjected(SimDevice::kScanner, "scanner");
  const double duration = state_.params.physics.scan_duration;
  if (Seconds(timeout) < duration) {
    state_.Advance(Seconds(timeout));
    throw DeviceTimeout(
        fmt::format("scanner: a scan takes {:.2f} s, the timeout is {:.3f} s", duration, Seconds(timeout)));
  }
  state_.ClearPlaceZone();
  state_.Advance(duration);
  if (state_.empty_scan_next) {
    state_.empty_scan_next = false;
    ++state_.events.empty_scans;
    return devices::Capture{.points_Sensor = {},
                            .unit = state_.params.cell.sensor.unit,
                            .X_BinSensor = state_.params.cell.sensor.X_BinSensor};
  }
  const physics::ScanResult scan =
      physics::ScanScene(state_.world->TubesInWorldBin(), state_.params.cell, state_.params.scanner,
                         physics::DeriveSeed(state_.params.seed, kScanStream + state_.scans++));
  devices::Capture capture;
  capture.unit = state_.params.cell.sensor.unit;
  capture.X_BinSensor = state_.params.cell.sensor.X_BinSensor;
  capture.points_Sensor = scan.points_Sensor;
  if (capture.unit != LengthUnit::kMetre) {
    const float scale = static_cast<float>(1.0 / MetresPer(capture.unit));
    for (Eigen::Vector3f& p : capture.points_Sensor) p *= scale;
  }
  return capture;
}

WrenchReading SimForceTorqueSensor::Read(Timeout /*timeout*/) {
  state_.ThrowIfInjected(SimDevice::kForceTorque, "F/T sensor");
  const Wrench raw = state_.RawFtReading();
  WrenchReading reading;
  reading.force = raw.force - state_.bias.force;
  reading.torque = raw.torque - state_.bias.torque;
  reading.sequence = ++state_.ft_sequence;
  if (state_.ft_spike_next) {
    state_.ft_spike_next = false;
    ++state_.events.ft_spikes;
    reading.force.z() += 25.0;
  }
  return reading;
}

void SimForceTorqueSensor::Bias(Timeout /*timeout*/) {
  state_.ThrowIfInjected(SimDevice::kForceTorque, "F/T sensor");
  state_.bias = state_.RawFtReading();
}

}  // namespace tubepick::devices::sim
