#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "core/wrench/wrench.h"
#include "devices/sim/sim_cell.h"
#include "devices/sim/sim_world.h"

namespace tubepick::devices::sim {

/// What the four simulated devices share: the world and the devices' own state.
struct SimCellState {
  SimCellState(const SimCellParams& params, const std::vector<physics::TubeGeometry>& tubes_Bin);

  SimCellParams params;
  std::unique_ptr<SimWorld> world;
  /// World time when construction ended, seconds.
  double start_time = 0.0;
  bool settled = false;

  bool servo_on = false;
  bool gripper_activated = false;
  GripperObject gripper_object = GripperObject::kAtPosition;
  mutable std::array<SimFault, 4> faults{SimFault::kNone, SimFault::kNone, SimFault::kNone, SimFault::kNone};
  /// The device's injected fault clears after it failed one call.
  mutable std::array<bool, 4> fault_once{false, false, false, false};
  /// Armed events (SimCell::ArmRobotAlarm / ArmSlip): simulated seconds until they happen, < 0 = none.
  double robot_alarm_in = -1.0;
  double slip_in = -1.0;
  /// SimCell::ArmSnag: the next opening while holding keeps what is held on the tool.
  bool snag_next_open = false;
  bool ft_spike_next = false;
  bool empty_scan_next = false;
  SimFaultEvents events;

  /// The F/T sensor's raw reading at the last Bias (sensor frame), subtracted from every read.
  Wrench bias;
  std::mt19937_64 noise_rng;
  std::uint64_t ft_sequence = 0;
  std::uint64_t scans = 0;

  /// Reach box of the TCP, bin frame.
  Eigen::AlignedBox3d workspace;

  /// Throws the injected fault of `device` (`who` prefixes the message), if any.
  void ThrowIfInjected(SimDevice device, const std::string& who) const;
  /// Advances the armed slip by `dt` seconds of robot motion; when it is due, whatever the gripper holds
  /// falls (the fingers stay, the gripper reports no object).
  void TickSlip(double dt);
  /// Advances the armed robot alarm by `dt`; when due: servo off and DeviceFault.
  void TickRobotAlarm(double dt);
  /// The conveyor (SimCellParams::place_zone_conveyor): carries off every tube at rest on the place
  /// zone; nothing without it.
  void ClearPlaceZone();
  /// Steps whole control steps with the gripper still for at least `seconds`.
  void Advance(double seconds);
  /// Raw F/T reading averaged over the F/T window (the world advances by it): payload wrench plus
  /// offsets plus noise, sensor frame.
  Wrench RawFtReading();
};

/// Simulated time `timeout` allows, seconds.
double Seconds(Timeout timeout);

class SimScanner final : public Scanner {
 public:
  explicit SimScanner(SimCellState& state) : state_(state) {}
  devices::Capture Scan(Timeout timeout) override;

 private:
  SimCellState& state_;
};

class SimRobot final : public Robot {
 public:
  explicit SimRobot(SimCellState& state) : state_(state) {}
  void MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Timeout timeout) override;
  void MoveThrough(const std::vector<Eigen::Vector3d>& waypoints, double speed, Timeout timeout) override;
  Eigen::Isometry3d CurrentPose(Timeout timeout) override;
  void ServoOn(Timeout timeout) override;
  std::optional<RobotStatus> Status(Timeout timeout) override;
  RobotLimits Limits() const override;

 protected:
  /// The simulation advances `seconds` with the tool still (injected slips and alarms tick on).
  void HoldFor(double seconds) override;

 private:
  void CheckReady() const;
  /// One Bullet substep with the tool where it was commanded; injected slips and alarms tick.
  void Tick();
  /// DeviceFault unless X_BinTcp is a finite rigid pose inside the reach box within the tilt limit.
  void CheckTarget(const Eigen::Isometry3d& X_BinTcp) const;
  double EffectiveSpeed(double speed) const;
  template <typename PoseAt>
  void Run(double length, double speed, const PoseAt& pose_at, const Eigen::Isometry3d& X_BinTcp_end,
           Timeout timeout);

  SimCellState& state_;
};

class SimGripper final : public Gripper {
 public:
  explicit SimGripper(SimCellState& state) : state_(state) {}
  void Activate(Timeout timeout) override;
  GripperStatus MoveTo(double opening, double speed, double force, Timeout timeout) override;
  GripperStatus Open(Timeout timeout) override;
  GripperStatus Close(double speed, double force, Timeout timeout) override;
  GripperStatus Status(Timeout timeout) override;

 private:
  GripperStatus Current() const;
  void CheckReady() const;

  SimCellState& state_;
};

class SimForceTorqueSensor final : public ForceTorqueSensor {
 public:
  explicit SimForceTorqueSensor(SimCellState& state) : state_(state) {}
  WrenchReading Read(Timeout timeout) override;
  void Bias(Timeout timeout) override;

 private:
  SimCellState& state_;
};

}  // namespace tubepick::devices::sim
