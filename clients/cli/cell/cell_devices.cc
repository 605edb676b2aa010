#include "clients/cli/cell/cell_devices.h"

#include <fmt/core.h>

#include "core/common/errors.h"
#include "devices/ati_netft.h"
#include "devices/exec_scanner.h"
#include "devices/file_replay_scanner.h"
#include "devices/netft_calibration.h"
#include "devices/robotiq_2f85.h"
#include "devices/yaskawa_hses.h"

namespace tubepick::cli {
namespace {

using devices::DevicesConfig;

void LoadCellDescription(const DevicesConfig& config, const std::string& cell_path, OpenedCell& opened) {
  if (!cell_path.empty()) {
    opened.cell = LoadCellConfig(cell_path);
    opened.cell_source = "--cell " + cell_path;
  } else if (!config.cell_file.empty()) {
    opened.cell = LoadCellConfig(config.cell_file);
    opened.cell_source = "devices file: " + config.cell_file;
  } else if (config.AllSim()) {
    opened.cell = opened.sim->cell();
    opened.cell_source = "the simulated cell";
  } else {
    throw InvalidArgument(
        "no cell description: a cell with real devices needs its bin, sensor pose and unit, place frame "
        "and tubes (give --cell FILE, or `cell: FILE` in the devices file; deploy/cell.example.yaml is an "
        "example)");
  }
}

}  // namespace

OpenedCell OpenCell(const DevicesConfig& config, const std::string& cell_path, OpenMode mode) {
  OpenedCell opened;
  if (config.AnySim()) {
    const devices::sim::Material material = devices::sim::ParseMaterial(config.sim.material, "sim.material");
    opened.sim = std::make_unique<devices::sim::SimCell>(
        devices::sim::SimCellParams::Thesis(material, config.sim.tubes, config.sim.seed));
  }
  LoadCellDescription(config, cell_path, opened);
  if (opened.sim && !config.AllSim() && !cell_path.empty()) {
    // A mixed cell: the simulated devices live in the simulation's own cell, say so.
    fmt::print("devices: the simulated devices use the thesis cell of sim.material, not {}\n",
               opened.cell_source);
  }
  devices::sim::SimCell* sim = opened.sim.get();

  auto open = [&](const char* name, auto&& make) {
    try {
      make();
    } catch (const std::exception& e) {
      opened.open_errors[name] = e.what();
    }
  };
  if (config.robot_driver == devices::RobotDriver::kYaskawaHses)
    open("robot", [&] { opened.robot = std::make_unique<devices::YaskawaHses>(config.yaskawa_hses); });
  if (config.gripper_driver == devices::GripperDriver::kRobotiq2F85Rtu)
    open("gripper", [&] { opened.gripper = std::make_unique<devices::Robotiq2F85>(config.robotiq_2f85); });
  if (config.ft_driver == devices::FtDriver::kAtiNetFtRdt)
    open("ft_sensor", [&] {
      devices::AtiNetFtParams params = config.ati_netft;
      if (config.ati_counts_from_sensor) {
        const devices::NetFtCalibration calibration =
            devices::ReadNetFtCalibration(params.host, config.ati_http_port, devices::Timeout(3000));
        params.counts_per_force = calibration.CountsPerNewton();
        params.counts_per_torque = calibration.CountsPerNewtonMetre();
        opened.ft_calibration =
            fmt::format("{} counts/{}, {} counts/{} from the box", calibration.counts_per_force,
                        calibration.force_unit, calibration.counts_per_torque, calibration.torque_unit);
      }
      opened.ft_sensor = std::make_unique<devices::AtiNetFt>(params);
    });
  open("scanner", [&] {
    if (config.scanner_driver == devices::ScannerDriver::kExec) {
      devices::ExecScannerParams params;
      params.command = config.exec_scanner.command;
      params.format = config.exec_scanner.format;
      params.sensor = opened.cell.sensor;
      opened.scanner = std::make_unique<devices::ExecScanner>(params);
    } else if (config.scanner_driver == devices::ScannerDriver::kFileReplay) {
      devices::FileReplayScannerParams params;
      params.directory = config.file_replay.directory;
      params.loop = config.file_replay.loop;
      params.sensor = opened.cell.sensor;
      opened.scanner = std::make_unique<devices::FileReplayScanner>(params);
    }
  });
  if (!opened.open_errors.empty() && mode == OpenMode::kAllOrThrow) {
    std::string why;
    for (const auto& [name, error] : opened.open_errors)
      why += fmt::format("{}{}: {}", why.empty() ? "" : "; ", name, error);
    throw devices::DeviceFault("cannot open the cell's devices: " + why);
  }
  opened.devices.robot =
      config.robot_driver == devices::RobotDriver::kSim ? &sim->robot() : opened.robot.get();
  opened.devices.gripper =
      config.gripper_driver == devices::GripperDriver::kSim ? &sim->gripper() : opened.gripper.get();
  opened.devices.ft_sensor =
      config.ft_driver == devices::FtDriver::kSim ? &sim->ft_sensor() : opened.ft_sensor.get();
  opened.devices.scanner =
      config.scanner_driver == devices::ScannerDriver::kSim ? &sim->scanner() : opened.scanner.get();
  return opened;
}

}  // namespace tubepick::cli
