#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "clients/cell/cell_controller.h"
#include "core/common/cell_config.h"
#include "devices/devices_config.h"
#include "devices/sim/sim_cell.h"

namespace tubepick::cli {

/// The four devices of a cell opened from a devices config: the real drivers it names and, when
/// any device is `sim`, one simulated cell behind all of those. Owns them; `devices` points into it.
struct OpenedCell {
  CellConfig cell;
  /// Where `cell` came from: "--cell FILE", "devices file: FILE" or "the simulated cell".
  std::string cell_source;
  std::unique_ptr<devices::sim::SimCell> sim;
  std::unique_ptr<devices::Robot> robot;
  std::unique_ptr<devices::Gripper> gripper;
  std::unique_ptr<devices::ForceTorqueSensor> ft_sensor;
  std::unique_ptr<devices::Scanner> scanner;
  cell::CellDevices devices;
  /// With OpenMode::kCollectErrors: why a device could not be opened (its pointer in `devices` is
  /// null), by "robot", "gripper", "ft_sensor", "scanner".
  std::map<std::string, std::string> open_errors;
  /// The F/T counts per unit read from the box (counts_from: sensor), for the operator; else empty.
  std::string ft_calibration;
};

enum class OpenMode {
  kAllOrThrow,     ///< a device that cannot be opened throws (naming every one that failed)
  kCollectErrors,  ///< record it in open_errors and go on (devices check)
};

/// The cell description of a devices config: `cell_path` (--cell) when given, else the devices
/// file's `cell`, else, for an all-simulated cell, the simulation's own cell.
/// @throws InvalidArgument when a cell with a real device has no cell description (no default may
///         stand in for a real bin), or a file cannot be read.
/// @throws devices::DeviceFault (kAllOrThrow) naming each device that could not be opened and why.
OpenedCell OpenCell(const devices::DevicesConfig& config, const std::string& cell_path,
                    OpenMode mode = OpenMode::kAllOrThrow);

}  // namespace tubepick::cli
