#include "clients/cli/cell/devices_check.h"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "clients/cli/cell/cell_devices.h"
#include "core/common/errors.h"
#include "core/modeling/cloud_plausibility.h"
#include "core/modeling/cloud_prepare.h"
#include "devices/devices_config.h"

namespace tubepick::cli {
namespace {

using devices::Timeout;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

struct CheckOptions {
  std::string devices_path;
  std::string cell_path;
  std::string json_path;
  double timeout_s = 5.0;
  double scan_timeout_s = 30.0;
  double ft_seconds = 1.0;
  double max_force_noise = 1.0;   ///< N, standard deviation over the window
  double max_torque_noise = 0.1;  ///< N·m
};

struct Row {
  Row(std::string device_name, std::string driver_name)
      : device(std::move(device_name)), driver(std::move(driver_name)) {}
  std::string device;
  std::string driver;
  bool pass = false;
  std::string detail;
  json values = json::object();
};

std::string Vec(const Eigen::Vector3d& v, int digits = 3) {
  return fmt::format("({:.{}f}, {:.{}f}, {:.{}f})", v.x(), digits, v.y(), digits, v.z(), digits);
}

std::string ObjectText(devices::GripperObject object) {
  switch (object) {
    case devices::GripperObject::kMoving:
      return "moving";
    case devices::GripperObject::kStoppedOpening:
      return "stopped opening (contact)";
    case devices::GripperObject::kStoppedClosing:
      return "stopped closing (object held)";
    case devices::GripperObject::kAtPosition:
      return "at position (no object)";
  }
  return "?";
}

/// Runs `check` and turns a device exception into a FAIL row naming it; a device that could not be
/// opened fails with why.
Row Guard(Row row, const OpenedCell& opened, const std::function<void(Row&)>& check) {
  if (const auto it = opened.open_errors.find(row.device); it != opened.open_errors.end()) {
    row.detail = "cannot open: " + it->second;
    return row;
  }
  try {
    check(row);
  } catch (const devices::DeviceTimeout& e) {
    row.pass = false;
    row.detail = fmt::format("no answer: {}", e.what());
  } catch (const std::exception& e) {
    row.pass = false;
    row.detail = e.what();
  }
  return row;
}

void CheckRobot(devices::Robot& robot, Timeout timeout, Row& row) {
  const std::optional<devices::RobotStatus> status = robot.Status(timeout);
  const Eigen::Isometry3d X_BinTcp = robot.CurrentPose(timeout);
  const Eigen::Vector3d p = X_BinTcp.translation();
  const Eigen::Vector3d z_Tcp = X_BinTcp.linear().col(2);
  const double tilt = std::acos(std::clamp(-z_Tcp.z(), -1.0, 1.0));
  row.values = {{"p_Bin_tcp", {p.x(), p.y(), p.z()}}, {"tilt_deg", tilt * 180.0 / M_PI}};
  std::string state = "status not readable by this driver";
  row.pass = true;
  if (status) {
    state = fmt::format("servo {}, {}{}", status->servo_on ? "on" : "off", status->running ? "moving, " : "",
                        status->alarm ? "ALARM" : (status->error ? "ERROR" : "no alarm"));
    row.values["servo_on"] = status->servo_on;
    row.values["alarm"] = status->alarm;
    row.values["error"] = status->error;
    row.values["status"] = status->detail;
    if (status->alarm || status->error) row.pass = false;
  }
  row.detail = fmt::format("TCP at {} m in the bin frame, {:.1f} deg from straight down; {}", Vec(p),
                           tilt * 180.0 / M_PI, state);
  const std::string reach = robot.Limits().Problem(X_BinTcp);
  if (!reach.empty()) {
    row.pass = false;
    row.detail += fmt::format(
        "; outside the configured reach ({}): is pose_bin_in_base (X_BaseBin) right, in metres?", reach);
  }
  if (status && (status->alarm || status->error))
    row.detail += " (reset the alarm on the pendant before a round)";
}

void CheckGripper(devices::Gripper& gripper, Timeout timeout, Row& row) {
  const devices::GripperStatus s = gripper.Status(timeout);
  row.values = {{"activated", s.activated},
                {"object", ObjectText(s.object)},
                {"opening_m", s.opening},
                {"fault", s.fault}};
  row.pass = s.fault == 0;
  // Before activation a 2F-85 reports no motion status (gGTO 0): its object status means nothing yet.
  row.detail = s.activated
                   ? fmt::format("activated, {}, opening {:.1f} mm", ObjectText(s.object), s.opening * 1000.0)
                   : fmt::format("answers, not activated (a round activates it), opening {:.1f} mm",
                                 s.opening * 1000.0);
  if (s.fault != 0) row.detail += fmt::format("; FAULT 0x{:02X}: {}", s.fault, s.fault_text);
  if (s.activated && s.object == devices::GripperObject::kStoppedClosing) {
    row.pass = false;
    row.detail += "; it reports an object held: empty the gripper before a round";
  }
}

void CheckFt(devices::ForceTorqueSensor& ft, Timeout timeout, const CheckOptions& o,
             const std::string& calibration, Row& row) {
  std::vector<devices::WrenchReading> readings;
  const auto end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.ft_seconds));
  while (Clock::now() < end) readings.push_back(ft.Read(timeout));
  Eigen::Vector3d f_mean = Eigen::Vector3d::Zero(), t_mean = Eigen::Vector3d::Zero();
  for (const auto& r : readings) {
    f_mean += r.force;
    t_mean += r.torque;
  }
  const double n = static_cast<double>(readings.size());
  f_mean /= n;
  t_mean /= n;
  double f_var = 0.0, t_var = 0.0;
  for (const auto& r : readings) {
    f_var += (r.force - f_mean).squaredNorm();
    t_var += (r.torque - t_mean).squaredNorm();
  }
  const double f_noise = std::sqrt(f_var / n), t_noise = std::sqrt(t_var / n);
  row.values = {{"readings", readings.size()},
                {"rate_hz", n / o.ft_seconds},
                {"force_mean_N", {f_mean.x(), f_mean.y(), f_mean.z()}},
                {"torque_mean_Nm", {t_mean.x(), t_mean.y(), t_mean.z()}},
                {"force_noise_N", f_noise},
                {"torque_noise_Nm", t_noise}};
  row.pass = f_noise <= o.max_force_noise && t_noise <= o.max_torque_noise && readings.size() >= 10;
  row.detail =
      fmt::format("{} readings in {:.1f} s; mean force {} N, torque {} N·m; noise {:.3f} N, {:.4f} N·m",
                  readings.size(), o.ft_seconds, Vec(f_mean, 2), Vec(t_mean, 3), f_noise, t_noise);
  if (!calibration.empty()) {
    row.detail += "; " + calibration;
    row.values["calibration"] = calibration;
  }
  if (readings.size() < 10) row.detail += "; fewer than 10 readings per second";
  if (f_noise > o.max_force_noise || t_noise > o.max_torque_noise)
    row.detail +=
        fmt::format("; noisier than {} N / {} N·m: check the counts per unit, the cabling and the tool",
                    o.max_force_noise, o.max_torque_noise);
}

void CheckScanner(devices::Scanner& scanner, const CellConfig& cell, Timeout timeout, Row& row) {
  const auto start = Clock::now();
  const devices::Capture capture = scanner.Scan(timeout);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  // The planner's own pass over a cloud (unit, bin frame, non-finite points, plausibility), keeping
  // no points: only the evidence is wanted.
  PrepareSpec spec;
  spec.crop_Bin = std::make_pair(Eigen::Vector3f::Ones().eval(), Eigen::Vector3f::Zero().eval());  // empty
  spec.raw_region_Bin = RawRegion::None();
  spec.bin = cell.bin;
  const PreparedCloud prepared = PrepareCloud(capture.points_Sensor, capture.unit, capture.X_BinSensor, spec);
  const CloudPlausibility& evidence = prepared.plausibility;
  const PlausibilityParams& params = spec.plausibility;
  row.values = {{"points", capture.points_Sensor.size()},
                {"finite_points", prepared.input_points - prepared.dropped_non_finite},
                {"scan_s", seconds},
                {"extent_m", {evidence.extent.x(), evidence.extent.y(), evidence.extent.z()}},
                {"inside_share", evidence.inside_share},
                {"floor_points", evidence.on_floor}};
  row.pass = evidence.plausible();
  row.detail = fmt::format(
      "{} points in {:.1f} s, extent {} m in the bin frame, {:.0f} % inside the bin, {} on its floor",
      capture.points_Sensor.size(), seconds, Vec(evidence.extent, 2), evidence.inside_share * 100.0,
      evidence.on_floor);
  if (!row.pass)
    row.detail +=
        "; " + DescribeImplausibleCloud(evidence, cell.bin, capture.unit, capture.X_BinSensor, params);
}

int Check(const CheckOptions& o) {
  const devices::DevicesConfig config = devices::LoadDevicesConfig(o.devices_path);
  if (!(o.timeout_s > 0.0) || !(o.scan_timeout_s > 0.0))
    throw InvalidArgument("--timeout / --scan-timeout: must be positive seconds");
  OpenedCell opened = OpenCell(config, o.cell_path, OpenMode::kCollectErrors);
  const Timeout timeout(std::llround(o.timeout_s * 1000.0));
  const Timeout scan_timeout(std::llround(o.scan_timeout_s * 1000.0));
  std::vector<Row> rows;
  rows.push_back(Guard(Row("robot", devices::ToString(config.robot_driver)), opened,
                       [&](Row& r) { CheckRobot(*opened.devices.robot, timeout, r); }));
  rows.push_back(Guard(Row("gripper", devices::ToString(config.gripper_driver)), opened,
                       [&](Row& r) { CheckGripper(*opened.devices.gripper, timeout, r); }));
  rows.push_back(Guard(Row("ft_sensor", devices::ToString(config.ft_driver)), opened, [&](Row& r) {
    CheckFt(*opened.devices.ft_sensor, timeout, o, opened.ft_calibration, r);
  }));
  rows.push_back(Guard(Row("scanner", devices::ToString(config.scanner_driver)), opened,
                       [&](Row& r) { CheckScanner(*opened.devices.scanner, opened.cell, scan_timeout, r); }));
  fmt::print("devices: {} (cell from {})\n", o.devices_path, opened.cell_source);
  bool all = true;
  json rows_json = json::array();
  for (const Row& row : rows) {
    fmt::print("{:<10} {:<17} {}  {}\n", row.device, row.driver, row.pass ? "PASS" : "FAIL", row.detail);
    all = all && row.pass;
    rows_json.push_back({{"device", row.device},
                         {"driver", row.driver},
                         {"pass", row.pass},
                         {"detail", row.detail},
                         {"values", row.values}});
  }
  fmt::print("{}\n",
             all ? "all devices pass" : "some devices FAIL: fix them before `tubepick cell --devices`");
  if (!o.json_path.empty()) {
    std::ofstream out(o.json_path);
    if (!out) throw InvalidArgument(fmt::format("--json {}: cannot open for writing", o.json_path));
    out << json{{"devices", o.devices_path}, {"pass", all}, {"rows", rows_json}}.dump(2) << '\n';
    if (!out.flush())
      throw InvalidArgument(fmt::format("--json {}: error writing (disk full?)", o.json_path));
  }
  return all ? 0 : 5;
}

}  // namespace

void AddDevicesCommand(CLI::App& app) {
  CLI::App* devices = app.add_subcommand("devices", "Commission a cell's devices (check)");
  devices->require_subcommand(1);
  auto o = std::make_shared<CheckOptions>();
  CLI::App* check = devices->add_subcommand(
      "check",
      "Connect to each device and read it without moving: one PASS/FAIL row per device (exit 0: all pass)");
  check->add_option("--devices", o->devices_path, "Devices YAML (tubepick cell --print-devices-config)")
      ->required()
      ->check(CLI::ExistingFile);
  check->add_option("--cell", o->cell_path, "Cell YAML (default: the devices file's `cell`)")
      ->check(CLI::ExistingFile);
  check->add_option("--json", o->json_path, "Write the rows with their values as JSON");
  check->add_option("--timeout", o->timeout_s, "Seconds per device request")->capture_default_str();
  check->add_option("--scan-timeout", o->scan_timeout_s, "Seconds for the one scan")->capture_default_str();
  check->callback([o] {
    const int status = Check(*o);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace tubepick::cli
