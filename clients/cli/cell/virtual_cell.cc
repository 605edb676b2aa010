#include "clients/cli/cell/virtual_cell.h"

#include <fmt/core.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>

#include "clients/cli/cell/scan_socket.h"
#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "devices/devices_config.h"
#include "devices/sim/sim_cell.h"
#include "devices/virtual/hses_server.h"
#include "devices/virtual/netft_http_server.h"
#include "devices/virtual/rdt_server.h"
#include "devices/virtual/robotiq_rtu_server.h"

namespace tubepick::cli {
namespace {

namespace fs = std::filesystem;

struct VirtualCellOptions {
  std::uint32_t tubes = 7;
  std::string material = "pvc";
  std::uint64_t seed = 1;
  std::string devices_out;
  std::string host = "127.0.0.1";
  double rest_s = 2.0;
};

struct ScanOptions {
  std::string socket;
  std::string out;
};

/// Where the virtual robot's base is: the bin 1.2 m in front of it and 0.3 m below, turned 90°
/// about z, so a wrong transform in the driver cannot go unnoticed.
Eigen::Isometry3d VirtualX_BaseBin() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(1.2, 0.0, -0.3);
  return X;
}

void WriteFileAtomically(const fs::path& path, const std::string& text) {
  const fs::path part = path.string() + ".part";
  {
    std::ofstream out(part);
    if (!out) throw InvalidArgument(fmt::format("cannot write {}", part.string()));
    out << text;
    if (!out.flush()) throw InvalidArgument(fmt::format("error writing {} (disk full?)", part.string()));
  }
  fs::rename(part, path);
}

std::string SelfExecutable() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("tubepick") : self.string();
}

/// Blocks SIGINT and SIGTERM in this thread and every thread started after it; WaitForSignal takes
/// them with sigwait.
sigset_t BlockStopSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  return set;
}

int Serve(const VirtualCellOptions& o) {
  if (o.devices_out.empty()) throw InvalidArgument("--devices-out: required");
  if (o.tubes == 0) throw InvalidArgument("--tubes: must be at least 1");
  const devices::sim::Material material = devices::sim::ParseMaterial(o.material, "--material");
  const sigset_t stop_signals = BlockStopSignals();

  devices::sim::SimCell sim(devices::sim::SimCellParams::Thesis(material, o.tubes, o.seed));
  std::mutex device_lock;
  const fs::path devices_path = fs::absolute(o.devices_out);
  const fs::path dir = devices_path.parent_path();
  const std::string stem = devices_path.stem().string();
  fs::create_directories(dir);

  devices::HsesServerOptions hses_options;
  hses_options.host = o.host;
  hses_options.X_BaseBin = VirtualX_BaseBin();
  devices::HsesServer hses(sim.robot(), device_lock, hses_options);
  devices::RdtServerOptions rdt_options;
  rdt_options.host = o.host;
  devices::RdtServer rdt(sim.ft_sensor(), device_lock, rdt_options);
  // The box's web server: the driver reads the counts per unit from it (counts_from: sensor).
  // Torque in N-mm, as some boxes are configured, so the unit conversion is exercised.
  devices::NetFtCalibration calibration{rdt_options.counts_per_force, rdt_options.counts_per_torque / 1000.0,
                                        "N", "N-mm"};
  devices::NetFtHttpServer netft_web(o.host, 0, calibration);
  devices::RobotiqRtuServer gripper(sim.gripper(), device_lock, {});
  const std::string socket = (dir / (stem + ".scan.sock")).string();
  ScanSocketServer scans(socket, [&](const std::string& out) {
    devices::Capture capture;
    {
      std::lock_guard lock(device_lock);
      capture = sim.scanner().Scan(devices::Timeout(30000));
    }
    WritePly(out + ".part", capture.points_Sensor);
    fs::rename(out + ".part", out);
    return std::string();
  });

  const fs::path cell_path = dir / (stem + ".cell.yaml");
  WriteFileAtomically(cell_path, DumpCellConfig(sim.cell()));
  devices::DevicesConfig config;
  config.cell_file = cell_path.filename().string();
  config.yaskawa_hses.host = o.host;
  config.yaskawa_hses.port = hses.port();
  config.yaskawa_hses.X_BaseBin = hses_options.X_BaseBin;
  config.yaskawa_hses.limits = sim.robot().Limits();
  config.robotiq_2f85.device = gripper.device_path();
  config.ati_netft.host = o.host;
  config.ati_netft.port = rdt.port();
  config.ati_counts_from_sensor = true;
  config.ati_http_port = netft_web.port();
  config.scanner_driver = devices::ScannerDriver::kExec;
  config.exec_scanner.command =
      fmt::format("'{}' virtual-cell scan --socket '{}' --out {{out}}", SelfExecutable(), socket);
  config.exec_scanner.format = "ply";
  config.Validate();
  WriteFileAtomically(devices_path, DumpDevicesConfig(config));

  fmt::print(
      "virtual-cell: {} {} tubes, seed {}: robot HSES udp://{}:{}, gripper Modbus RTU {}, F/T RDT "
      "udp://{}:{}, "
      "scanner exec via {}\n",
      o.tubes, o.material, o.seed, o.host, hses.port(), gripper.device_path(), o.host, rdt.port(), socket);
  fmt::print("virtual-cell: ready: tubepick cell --devices {} --rounds 1\n", devices_path.string());
  std::fflush(stdout);

  int signo = 0;
  sigwait(&stop_signals, &signo);
  spdlog::info("virtual-cell: {} received", signo == SIGINT ? "SIGINT" : "SIGTERM");

  std::lock_guard lock(device_lock);  // no device call runs while the world is counted
  sim.Advance(o.rest_s);              // what fell comes to rest first
  const std::uint32_t in_bin = sim.TubesInBin();
  const std::uint32_t placed = sim.TubesInPlaceZone();
  const auto outside = static_cast<std::uint32_t>(sim.TubesElsewhere() + sim.HeldTubes().size());
  fmt::print("virtual-cell: tubes_in_bin={} placed={} outside={}\n", in_bin, placed, outside);
  std::fflush(stdout);
  std::error_code ec;
  fs::remove(devices_path, ec);
  return outside == 0 ? 0 : 3;
}

}  // namespace

void AddVirtualCellCommand(CLI::App& app) {
  auto o = std::make_shared<VirtualCellOptions>();
  auto scan = std::make_shared<ScanOptions>();
  CLI::App* cmd = app.add_subcommand("virtual-cell",
                                     "Serve the simulated cell behind the real protocols (HSES, RDT, Modbus "
                                     "RTU on a pty, an exec scanner) and "
                                     "write the devices YAML pointing at it; until SIGINT/SIGTERM");
  cmd->add_option("--tubes", o->tubes, "Tubes dropped into the bin")->capture_default_str();
  cmd->add_option("--material", o->material, "pvc or rubber")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the simulated bin")->capture_default_str();
  cmd->add_option("--devices-out", o->devices_out,
                  "Devices YAML to write (and FILE's stem + .cell.yaml, .scan.sock beside it)");
  cmd->add_option("--host", o->host, "Loopback address the UDP servers bind")->capture_default_str();
  CLI::App* scan_cmd = cmd->add_subcommand(
      "scan", "The exec scanner's bridge: ask a running virtual cell for one scan written to --out");
  scan_cmd->add_option("--socket", scan->socket, "The virtual cell's scan socket")->required();
  scan_cmd->add_option("--out", scan->out, "PLY file to write")->required();
  scan_cmd->callback([scan] {
    const std::string error = RequestScan(scan->socket, scan->out);
    if (!error.empty()) {
      fmt::print(stderr, "virtual-cell scan: {}\n", error);
      throw CLI::RuntimeError(1);
    }
  });
  cmd->callback([cmd, scan_cmd, o] {
    if (cmd->got_subcommand(scan_cmd)) return;
    const int status = Serve(*o);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace tubepick::cli
