#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "devices/ati_netft.h"
#include "devices/robotiq_2f85.h"
#include "devices/yaskawa_hses.h"

namespace tubepick::devices {

/// Which driver runs one device of the cell. kSim: the simulated cell (devices/sim, opened by the
/// command that runs the cell, since devices/ does not depend on the simulation).
enum class RobotDriver { kYaskawaHses, kSim };
enum class GripperDriver { kRobotiq2F85Rtu, kSim };
enum class FtDriver { kAtiNetFtRdt, kSim };
enum class ScannerDriver { kFileReplay, kExec, kSim };

/// "yaskawa-hses", "robotiq-2f85-rtu", "ati-netft-rdt", "file-replay", "exec", "sim".
std::string ToString(RobotDriver driver);
std::string ToString(GripperDriver driver);
std::string ToString(FtDriver driver);
std::string ToString(ScannerDriver driver);

/// A scanner bridged through a vendor tool: `command` (run with /bin/sh -c) writes one cloud file
/// (PLY or PCD) to the path that replaces every `{out}` in it, then exits 0. The usual bridge to a
/// vendor SDK (Zivid, Photoneo) without linking it.
struct ExecScannerConfig {
  std::string command;
  /// Extension of the file the command writes: ply or pcd.
  std::string format = "ply";
};

struct FileReplayConfig {
  std::string directory;
  bool loop = false;
};

/// The simulated devices' cell (used by every device whose driver is sim).
struct SimDevicesConfig {
  std::string material = "pvc";
  std::uint32_t tubes = 7;
  std::uint64_t seed = 1;
};

/// The four devices of a cell and how to reach them (tubepick cell --devices FILE). The scanner's
/// pose and unit are the cell's `sensor` section (--cell), as for the planner.
struct DevicesConfig {
  /// The cell YAML (bin, sensor pose and unit, place frame, tubes) of this cell; a relative path is
  /// relative to the devices file. Empty: give --cell (a real cell has no default cell).
  std::string cell_file;
  RobotDriver robot_driver = RobotDriver::kYaskawaHses;
  YaskawaHsesParams yaskawa_hses;
  GripperDriver gripper_driver = GripperDriver::kRobotiq2F85Rtu;
  Robotiq2F85Params robotiq_2f85;
  FtDriver ft_driver = FtDriver::kAtiNetFtRdt;
  AtiNetFtParams ati_netft;
  /// Counts per unit from the box's own active configuration (netftapi2.xml over HTTP on
  /// ati_http_port) instead of ati_netft's counts_per_force / counts_per_torque.
  bool ati_counts_from_sensor = false;
  std::uint16_t ati_http_port = 80;
  ScannerDriver scanner_driver = ScannerDriver::kExec;
  ExecScannerConfig exec_scanner;
  FileReplayConfig file_replay;
  SimDevicesConfig sim;

  /// True when any device is simulated.
  bool AnySim() const;
  /// True when every device is simulated.
  bool AllSim() const;
  /// Range and consistency checks of what the chosen drivers use.
  /// @throws InvalidArgument naming the key and the value.
  void Validate() const;
};

/// Reads a devices YAML (strict: unknown keys, a driver's section given for another driver and bad
/// values are errors naming the key path) and validates it.
/// @throws InvalidArgument.
DevicesConfig LoadDevicesConfig(const std::string& path);
DevicesConfig ParseDevicesConfig(const std::string& yaml_text, const std::string& what);
/// Every key with its comment; ParseDevicesConfig reads it back to the same values.
std::string DumpDevicesConfig(const DevicesConfig& config);
/// The commented example `tubepick cell --print-devices-config` prints: the real drivers with
/// their factory addresses.
std::string ExampleDevicesConfig();

}  // namespace tubepick::devices
