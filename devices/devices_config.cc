#include "devices/devices_config.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/common/config_fields.h"
#include "core/common/errors.h"
#include "core/common/yaml_reader.h"

namespace tubepick::devices {

// The file's shape: per device a `driver` and one section per driver, only the chosen driver's
// section may be given. Sections hold YAML-friendly types (int ports); Build() turns them into the
// drivers' params.

struct HsesSection {
  std::string host = "192.168.255.1";
  int port = hses::kDefaultPort;
  int tool = 0;
  int user_frame = 0;
  Eigen::Isometry3d X_BaseUser = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_BaseBin = Eigen::Isometry3d::Identity();
  double default_speed = 0.1;
  double max_speed = 0.25;
  Eigen::Vector3d reach_min{-1.5, -1.5, -0.1};
  Eigen::Vector3d reach_max{1.5, 1.5, 1.5};
  double max_tilt = M_PI / 3.0;
  Timeout request_timeout{500};
  Timeout poll_interval{10};
};

struct RobotiqSection {
  std::string device = "/dev/ttyUSB0";
  int slave_id = robotiq::kDefaultSlaveId;
  int baud = robotiq::kDefaultBaud;
  Timeout response_timeout{200};
  Timeout poll_period{10};
};

struct NetFtSection {
  std::string host = "192.168.1.1";
  int port = rdt::kDefaultPort;
  std::string counts_from = "config";
  int http_port = 80;
  double counts_per_force = 1'000'000.0;
  double counts_per_torque = 1'000'000.0;
};

struct RobotSection {
  std::string driver = "yaskawa-hses";
  std::optional<HsesSection> yaskawa_hses;
};
struct GripperSection {
  std::string driver = "robotiq-2f85-rtu";
  std::optional<RobotiqSection> robotiq_2f85_rtu;
};
struct FtSection {
  std::string driver = "ati-netft-rdt";
  std::optional<NetFtSection> ati_netft_rdt;
};
struct ScannerSection {
  std::string driver = "exec";
  std::optional<ExecScannerConfig> exec;
  std::optional<FileReplayConfig> file_replay;
};

struct DevicesFile {
  std::string cell;
  RobotSection robot;
  GripperSection gripper;
  FtSection ft_sensor;
  ScannerSection scanner;
  std::optional<SimDevicesConfig> sim;
};

template <typename Visit>
void DescribeFields(Visit& v, HsesSection& s) {
  v("host", s.host, "YRC1000 address (its factory default is 192.168.255.1)");
  v("port", s.port, "HSES robot-control port, UDP");
  v("tool", s.tool, "tool file number the TCP is taught in (0..63)");
  v("user_frame", s.user_frame, "user frame the moves are given in (1..63), or 0: base coordinates");
  v.Pose("pose_user_in_base", s.X_BaseUser, "X_BaseUser: that user frame in the base frame (user_frame > 0)");
  v.Pose("pose_bin_in_base", s.X_BaseBin, "X_BaseBin: the bin frame (floor centre, z up) in the base frame");
  v("default_speed", s.default_speed, "m/s when a move asks for none");
  v("max_speed", s.max_speed, "m/s, faster requests are clamped");
  v("reach_min", s.reach_min, "reachable TCP box, bin frame, m");
  v("reach_max", s.reach_max);
  v.Degrees("max_tilt_deg", s.max_tilt, "largest angle of the TCP z axis from straight down");
  v.Seconds("request_timeout", s.request_timeout, "longest wait for one answer; reads are sent again");
  v.Seconds("poll_interval", s.poll_interval, "status polls while a move runs");
}

template <typename Visit>
void DescribeFields(Visit& v, RobotiqSection& s) {
  v("device", s.device, "serial device of the RS-485 adapter");
  v("slave_id", s.slave_id, "Modbus slave id (the gripper's default is 9)");
  v("baud", s.baud, "8N1");
  v.Seconds("response_timeout", s.response_timeout, "per Modbus request");
  v.Seconds("poll_period", s.poll_period, "status polls while the fingers move");
}

template <typename Visit>
void DescribeFields(Visit& v, NetFtSection& s) {
  v("host", s.host, "Net F/T address (its factory default is 192.168.1.1)");
  v("port", s.port, "RDT port, UDP");
  v("counts_from", s.counts_from,
    "config: the two counts below; sensor: the box's active configuration (netftapi2.xml over HTTP)");
  v("http_port", s.http_port, "the box's web server (counts_from: sensor)");
  v("counts_per_force", s.counts_per_force,
    "counts per N: cfgcpf of the active configuration (the box's netftapi2.xml)");
  v("counts_per_torque", s.counts_per_torque, "counts per N·m: cfgcpt of the active configuration");
}

template <typename Visit>
void DescribeFields(Visit& v, ExecScannerConfig& s) {
  v("command", s.command,
    "run with /bin/sh -c for every scan; {out} is replaced by the file it must write; exit 0");
  v("format", s.format, "ply or pcd: what the command writes");
}

template <typename Visit>
void DescribeFields(Visit& v, FileReplayConfig& s) {
  v("directory", s.directory, "*.ply and *.pcd replayed in natural name order");
  v("loop", s.loop, "start again after the last file");
}

template <typename Visit>
void DescribeFields(Visit& v, SimDevicesConfig& s) {
  v("material", s.material, "pvc or rubber (thesis Table 5.2)");
  v("tubes", s.tubes, "tubes dropped into the simulated bin");
  v("seed", s.seed);
}

template <typename Visit>
void DescribeFields(Visit& v, RobotSection& s) {
  v("driver", s.driver, "yaskawa-hses or sim");
  v.OptionalSection("yaskawa_hses", s.yaskawa_hses, "Yaskawa YRC1000 over HSES (UDP)");
}
template <typename Visit>
void DescribeFields(Visit& v, GripperSection& s) {
  v("driver", s.driver, "robotiq-2f85-rtu or sim");
  v.OptionalSection("robotiq_2f85_rtu", s.robotiq_2f85_rtu, "Robotiq 2F-85 over Modbus RTU (RS-485)");
}
template <typename Visit>
void DescribeFields(Visit& v, FtSection& s) {
  v("driver", s.driver, "ati-netft-rdt or sim");
  v.OptionalSection("ati_netft_rdt", s.ati_netft_rdt, "ATI Net F/T over RDT (UDP)");
}
template <typename Visit>
void DescribeFields(Visit& v, ScannerSection& s) {
  v("driver", s.driver, "exec, file-replay or sim; its pose and unit are the cell's sensor section");
  v.OptionalSection("exec", s.exec, "a command that writes one cloud file per scan");
  v.OptionalSection("file_replay", s.file_replay, "recorded clouds, one per scan");
}
template <typename Visit>
void DescribeFields(Visit& v, DevicesFile& f) {
  v("cell", f.cell,
    "the cell YAML (bin, sensor pose and unit, place frame, tubes), relative to this file; --cell overrides");
  v.Section("robot", f.robot);
  v.Section("gripper", f.gripper);
  v.Section("ft_sensor", f.ft_sensor);
  v.Section("scanner", f.scanner);
  v.OptionalSection("sim", f.sim, "the simulated cell behind every device whose driver is sim");
}

namespace {

constexpr std::string_view kHeader =
    "Devices of one cell (tubepick cell --devices FILE, tubepick devices check --devices FILE).\n"
    "Per device a driver and that driver's section; unknown keys, and a section of a driver not\n"
    "chosen, are errors. Units: m, m/s, s, degrees where the key says _deg.";

template <typename E>
E ParseDriver(const std::string& text, const std::string& path, std::initializer_list<E> drivers) {
  std::string names;
  for (E d : drivers) {
    if (ToString(d) == text) return d;
    names += (names.empty() ? "" : ", ") + ToString(d);
  }
  throw InvalidArgument(fmt::format("{}: unknown driver '{}' ({})", path, text, names));
}

template <typename Section>
Section Required(const std::optional<Section>& section, const std::string& path, const std::string& driver) {
  if (!section)
    throw InvalidArgument(fmt::format("{}: missing: driver {} needs its connection", path, driver));
  return *section;
}

template <typename Section>
void Unused(const std::optional<Section>& section, const std::string& path, const std::string& driver) {
  if (section)
    throw InvalidArgument(
        fmt::format("{}: given, but the driver is {} (a section of another driver is "
                    "ignored by nothing: remove it or change the driver)",
                    path, driver));
}

std::uint16_t Port(int port, const std::string& path) {
  if (port < 1 || port > 65535)
    throw InvalidArgument(fmt::format("{}: a UDP port in 1..65535, got {}", path, port));
  return static_cast<std::uint16_t>(port);
}

YaskawaHsesParams Build(const HsesSection& s) {
  YaskawaHsesParams p;
  p.host = s.host;
  p.port = Port(s.port, "robot.yaskawa_hses.port");
  p.tool = s.tool;
  p.user_frame = s.user_frame;
  p.X_BaseUser = s.X_BaseUser;
  p.X_BaseBin = s.X_BaseBin;
  p.default_speed = s.default_speed;
  p.limits.max_speed = s.max_speed;
  p.limits.reach_Bin = Eigen::AlignedBox3d(s.reach_min, s.reach_max);
  p.limits.max_tilt = s.max_tilt;
  p.request_timeout = s.request_timeout;
  p.poll_interval = s.poll_interval;
  return p;
}

Robotiq2F85Params Build(const RobotiqSection& s) {
  Robotiq2F85Params p;
  p.device = s.device;
  p.slave_id = s.slave_id;
  p.baud = s.baud;
  p.response_timeout = s.response_timeout;
  p.poll_period = s.poll_period;
  return p;
}

AtiNetFtParams Build(const NetFtSection& s) {
  AtiNetFtParams p;
  p.host = s.host;
  p.port = Port(s.port, "ft_sensor.ati_netft_rdt.port");
  p.counts_per_force = s.counts_per_force;
  p.counts_per_torque = s.counts_per_torque;
  return p;
}

DevicesConfig FromFile(const DevicesFile& f) {
  DevicesConfig c;
  c.cell_file = f.cell;
  c.robot_driver =
      ParseDriver(f.robot.driver, "robot.driver", {RobotDriver::kYaskawaHses, RobotDriver::kSim});
  if (c.robot_driver == RobotDriver::kYaskawaHses)
    c.yaskawa_hses = Build(Required(f.robot.yaskawa_hses, "robot.yaskawa_hses", f.robot.driver));
  else
    Unused(f.robot.yaskawa_hses, "robot.yaskawa_hses", f.robot.driver);

  c.gripper_driver =
      ParseDriver(f.gripper.driver, "gripper.driver", {GripperDriver::kRobotiq2F85Rtu, GripperDriver::kSim});
  if (c.gripper_driver == GripperDriver::kRobotiq2F85Rtu)
    c.robotiq_2f85 =
        Build(Required(f.gripper.robotiq_2f85_rtu, "gripper.robotiq_2f85_rtu", f.gripper.driver));
  else
    Unused(f.gripper.robotiq_2f85_rtu, "gripper.robotiq_2f85_rtu", f.gripper.driver);

  c.ft_driver = ParseDriver(f.ft_sensor.driver, "ft_sensor.driver", {FtDriver::kAtiNetFtRdt, FtDriver::kSim});
  if (c.ft_driver == FtDriver::kAtiNetFtRdt) {
    const NetFtSection section =
        Required(f.ft_sensor.ati_netft_rdt, "ft_sensor.ati_netft_rdt", f.ft_sensor.driver);
    c.ati_netft = Build(section);
    if (section.counts_from != "config" && section.counts_from != "sensor")
      throw InvalidArgument(fmt::format("ft_sensor.ati_netft_rdt.counts_from: config or sensor, got '{}'",
                                        section.counts_from));
    c.ati_counts_from_sensor = section.counts_from == "sensor";
    c.ati_http_port = Port(section.http_port, "ft_sensor.ati_netft_rdt.http_port");
  } else
    Unused(f.ft_sensor.ati_netft_rdt, "ft_sensor.ati_netft_rdt", f.ft_sensor.driver);

  c.scanner_driver = ParseDriver(f.scanner.driver, "scanner.driver",
                                 {ScannerDriver::kExec, ScannerDriver::kFileReplay, ScannerDriver::kSim});
  if (c.scanner_driver == ScannerDriver::kExec)
    c.exec_scanner = Required(f.scanner.exec, "scanner.exec", f.scanner.driver);
  else
    Unused(f.scanner.exec, "scanner.exec", f.scanner.driver);
  if (c.scanner_driver == ScannerDriver::kFileReplay)
    c.file_replay = Required(f.scanner.file_replay, "scanner.file_replay", f.scanner.driver);
  else
    Unused(f.scanner.file_replay, "scanner.file_replay", f.scanner.driver);

  if (c.AnySim()) {
    if (f.sim) c.sim = *f.sim;
  } else if (f.sim) {
    throw InvalidArgument("sim: given, but no device's driver is sim");
  }
  return c;
}

HsesSection ToSection(const YaskawaHsesParams& p) {
  HsesSection s;
  s.host = p.host;
  s.port = p.port;
  s.tool = p.tool;
  s.user_frame = p.user_frame;
  s.X_BaseUser = p.X_BaseUser;
  s.X_BaseBin = p.X_BaseBin;
  s.default_speed = p.default_speed;
  s.max_speed = p.limits.max_speed;
  s.reach_min = p.limits.reach_Bin.min();
  s.reach_max = p.limits.reach_Bin.max();
  s.max_tilt = p.limits.max_tilt;
  s.request_timeout = p.request_timeout;
  s.poll_interval = p.poll_interval;
  return s;
}

DevicesFile ToFile(const DevicesConfig& c) {
  DevicesFile f;
  f.cell = c.cell_file;
  f.robot.driver = ToString(c.robot_driver);
  if (c.robot_driver == RobotDriver::kYaskawaHses) f.robot.yaskawa_hses = ToSection(c.yaskawa_hses);
  f.gripper.driver = ToString(c.gripper_driver);
  if (c.gripper_driver == GripperDriver::kRobotiq2F85Rtu) {
    const Robotiq2F85Params& p = c.robotiq_2f85;
    f.gripper.robotiq_2f85_rtu =
        RobotiqSection{p.device, p.slave_id, p.baud, p.response_timeout, p.poll_period};
  }
  f.ft_sensor.driver = ToString(c.ft_driver);
  if (c.ft_driver == FtDriver::kAtiNetFtRdt) {
    const AtiNetFtParams& p = c.ati_netft;
    f.ft_sensor.ati_netft_rdt = NetFtSection{p.host,
                                             p.port,
                                             c.ati_counts_from_sensor ? "sensor" : "config",
                                             c.ati_http_port,
                                             p.counts_per_force,
                                             p.counts_per_torque};
  }
  f.scanner.driver = ToString(c.scanner_driver);
  if (c.scanner_driver == ScannerDriver::kExec) f.scanner.exec = c.exec_scanner;
  if (c.scanner_driver == ScannerDriver::kFileReplay) f.scanner.file_replay = c.file_replay;
  if (c.AnySim()) f.sim = c.sim;
  return f;
}

void RequireIn(double value, double lo, double hi, const std::string& path, const std::string& unit) {
  if (!(value >= lo && value <= hi))
    throw InvalidArgument(fmt::format("{}: {} {} is outside [{}, {}]", path, value, unit, lo, hi));
}

void RequirePose(const Eigen::Isometry3d& X, const std::string& path) {
  if (!X.matrix().allFinite()) throw InvalidArgument(path + ": not a finite pose");
  if (X.translation().norm() > 20.0)
    throw InvalidArgument(fmt::format("{}.position: {:.3f} m from the origin: metres expected (millimetres?)",
                                      path, X.translation().norm()));
}

}  // namespace

std::string ToString(RobotDriver d) { return d == RobotDriver::kSim ? "sim" : "yaskawa-hses"; }
std::string ToString(GripperDriver d) { return d == GripperDriver::kSim ? "sim" : "robotiq-2f85-rtu"; }
std::string ToString(FtDriver d) { return d == FtDriver::kSim ? "sim" : "ati-netft-rdt"; }
std::string ToString(ScannerDriver d) {
  switch (d) {
    case ScannerDriver::kFileReplay:
      return "file-replay";
    case ScannerDriver::kExec:
      return "exec";
    case ScannerDriver::kSim:
      return "sim";
  }
  return "?";
}

bool DevicesConfig::AnySim() const {
  return robot_driver == RobotDriver::kSim || gripper_driver == GripperDriver::kSim ||
         ft_driver == FtDriver::kSim || scanner_driver == ScannerDriver::kSim;
}

bool DevicesConfig::AllSim() const {
  return robot_driver == RobotDriver::kSim && gripper_driver == GripperDriver::kSim &&
         ft_driver == FtDriver::kSim && scanner_driver == ScannerDriver::kSim;
}

void DevicesConfig::Validate() const {
  if (robot_driver == RobotDriver::kYaskawaHses) {
    const YaskawaHsesParams& p = yaskawa_hses;
    const std::string k = "robot.yaskawa_hses.";
    if (p.host.empty()) throw InvalidArgument(k + "host: empty");
    if (p.tool < 0 || p.tool > 63) throw InvalidArgument(fmt::format("{}tool: 0..63, got {}", k, p.tool));
    if (p.user_frame < 0 || p.user_frame > 63)
      throw InvalidArgument(fmt::format("{}user_frame: 0 (base) or 1..63, got {}", k, p.user_frame));
    RequirePose(p.X_BaseBin, k + "pose_bin_in_base");
    RequirePose(p.X_BaseUser, k + "pose_user_in_base");
    RequireIn(p.default_speed, 0.001, 2.0, k + "default_speed", "m/s");
    RequireIn(p.limits.max_speed, 0.001, 2.0, k + "max_speed", "m/s");
    if (!(p.limits.reach_Bin.min().array() < p.limits.reach_Bin.max().array()).all())
      throw InvalidArgument(k + "reach_min: must be below reach_max on every axis");
    RequireIn(p.limits.max_tilt, 0.0, M_PI, k + "max_tilt_deg", "rad");
    RequireIn(static_cast<double>(p.request_timeout.count()), 1, 60000, k + "request_timeout", "ms");
    RequireIn(static_cast<double>(p.poll_interval.count()), 1, 1000, k + "poll_interval", "ms");
  }
  if (gripper_driver == GripperDriver::kRobotiq2F85Rtu) {
    const Robotiq2F85Params& p = robotiq_2f85;
    const std::string k = "gripper.robotiq_2f85_rtu.";
    if (p.device.empty()) throw InvalidArgument(k + "device: empty");
    if (p.slave_id < 1 || p.slave_id > 247)
      throw InvalidArgument(fmt::format("{}slave_id: 1..247, got {}", k, p.slave_id));
    static constexpr int kBauds[] = {9600, 19200, 38400, 57600, 115200};
    if (std::find(std::begin(kBauds), std::end(kBauds), p.baud) == std::end(kBauds))
      throw InvalidArgument(
          fmt::format("{}baud: one of 9600, 19200, 38400, 57600, 115200, got {}", k, p.baud));
    RequireIn(static_cast<double>(p.response_timeout.count()), 1, 10000, k + "response_timeout", "ms");
    RequireIn(static_cast<double>(p.poll_period.count()), 1, 1000, k + "poll_period", "ms");
  }
  if (ft_driver == FtDriver::kAtiNetFtRdt) {
    const std::string k = "ft_sensor.ati_netft_rdt.";
    if (ati_netft.host.empty()) throw InvalidArgument(k + "host: empty");
    RequireIn(ati_netft.counts_per_force, 1.0, 1e9, k + "counts_per_force", "counts/N");
    RequireIn(ati_netft.counts_per_torque, 1.0, 1e9, k + "counts_per_torque", "counts/N·m");
  }
  if (scanner_driver == ScannerDriver::kExec) {
    if (exec_scanner.command.find("{out}") == std::string::npos)
      throw InvalidArgument(fmt::format(
          "scanner.exec.command: '{}' has no {{out}}: the command must write the cloud to the path given "
          "as {{out}}",
          exec_scanner.command));
    if (exec_scanner.format != "ply" && exec_scanner.format != "pcd")
      throw InvalidArgument(fmt::format("scanner.exec.format: ply or pcd, got '{}'", exec_scanner.format));
  }
  if (scanner_driver == ScannerDriver::kFileReplay && file_replay.directory.empty())
    throw InvalidArgument("scanner.file_replay.directory: empty");
  if (AnySim()) {
    if (sim.material != "pvc" && sim.material != "rubber")
      throw InvalidArgument(fmt::format("sim.material: pvc or rubber, got '{}'", sim.material));
    if (sim.tubes < 1 || sim.tubes > 50)
      throw InvalidArgument(fmt::format("sim.tubes: 1..50, got {}", sim.tubes));
  }
}

DevicesConfig ParseDevicesConfig(const std::string& yaml_text, const std::string& what) {
  DevicesFile file;
  ParseFields(yaml_text, what, file);
  DevicesConfig config = FromFile(file);
  config.Validate();
  return config;
}

DevicesConfig LoadDevicesConfig(const std::string& path) {
  try {
    DevicesConfig config = ParseDevicesConfig(ReadTextFile(path), path);
    if (!config.cell_file.empty() && std::filesystem::path(config.cell_file).is_relative())
      config.cell_file =
          (std::filesystem::path(path).parent_path() / config.cell_file).lexically_normal().string();
    return config;
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("devices config '" + path + "': " + e.what());
  }
}

std::string DumpDevicesConfig(const DevicesConfig& config) { return DumpFields(ToFile(config), kHeader); }

std::string ExampleDevicesConfig() {
  DevicesConfig c;
  c.cell_file = "cell.example.yaml";
  c.exec_scanner.command = "/opt/scanner/capture-ply --output {out}";
  // A bin 1.2 m in front of the robot base, 0.1 m below it; the bin frame's axes along the base's.
  c.yaskawa_hses.X_BaseBin = Eigen::Isometry3d(Eigen::Translation3d(1.2, 0.0, -0.1));
  return DumpDevicesConfig(c);
}

}  // namespace tubepick::devices
