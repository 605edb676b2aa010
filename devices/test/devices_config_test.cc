#include "devices/devices_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/common/errors.h"

namespace tubepick::devices {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseDevicesConfig(yaml, "test");
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

constexpr const char* kRealCell = R"(
cell: cell.yaml
robot:
  driver: yaskawa-hses
  yaskawa_hses:
    host: 10.0.0.2
    port: 10040
    tool: 3
    pose_bin_in_base: {position: [1.1, -0.2, -0.35], orientation_xyzw: [0, 0, 0.7071068, 0.7071068]}
    request_timeout: 0.25
gripper:
  driver: robotiq-2f85-rtu
  robotiq_2f85_rtu: {device: /dev/ttyUSB1, slave_id: 9, baud: 115200}
ft_sensor:
  driver: ati-netft-rdt
  ati_netft_rdt: {host: 10.0.0.3, counts_per_force: 1000000, counts_per_torque: 1000}
scanner:
  driver: exec
  exec: {command: "zivid-capture --out {out}", format: ply}
)";

TEST(DevicesConfig, ReadsEveryDriverSection) {
  const DevicesConfig c = ParseDevicesConfig(kRealCell, "test");
  EXPECT_EQ(c.cell_file, "cell.yaml");
  EXPECT_EQ(c.robot_driver, RobotDriver::kYaskawaHses);
  EXPECT_EQ(c.yaskawa_hses.host, "10.0.0.2");
  EXPECT_EQ(c.yaskawa_hses.tool, 3);
  EXPECT_EQ(c.yaskawa_hses.request_timeout.count(), 250);
  EXPECT_NEAR(c.yaskawa_hses.X_BaseBin.translation().x(), 1.1, 1e-12);
  EXPECT_NEAR((c.yaskawa_hses.X_BaseBin.linear() * Eigen::Vector3d::UnitX()).y(), 1.0, 1e-6);
  EXPECT_EQ(c.robotiq_2f85.device, "/dev/ttyUSB1");
  EXPECT_EQ(c.ati_netft.host, "10.0.0.3");
  EXPECT_EQ(c.ati_netft.port, 49152);
  EXPECT_DOUBLE_EQ(c.ati_netft.counts_per_torque, 1000.0);
  EXPECT_EQ(c.scanner_driver, ScannerDriver::kExec);
  EXPECT_EQ(c.exec_scanner.command, "zivid-capture --out {out}");
  EXPECT_FALSE(c.AnySim());
}

TEST(DevicesConfig, TheDumpAndTheExampleReadBackToTheSameValues) {
  const DevicesConfig c = ParseDevicesConfig(kRealCell, "test");
  const DevicesConfig back = ParseDevicesConfig(DumpDevicesConfig(c), "dump");
  EXPECT_EQ(back.yaskawa_hses.host, c.yaskawa_hses.host);
  EXPECT_TRUE(back.yaskawa_hses.X_BaseBin.isApprox(c.yaskawa_hses.X_BaseBin, 1e-12));
  EXPECT_EQ(back.robotiq_2f85.slave_id, c.robotiq_2f85.slave_id);
  EXPECT_EQ(back.exec_scanner.command, c.exec_scanner.command);
  const DevicesConfig example = ParseDevicesConfig(ExampleDevicesConfig(), "example");
  EXPECT_EQ(example.robot_driver, RobotDriver::kYaskawaHses);
  EXPECT_EQ(example.scanner_driver, ScannerDriver::kExec);
  EXPECT_THAT(ExampleDevicesConfig(), HasSubstr("# "));  // commented
}

TEST(DevicesConfig, AllSimNeedsNoConnection) {
  const DevicesConfig c = ParseDevicesConfig(R"(
robot: {driver: sim}
gripper: {driver: sim}
ft_sensor: {driver: sim}
scanner: {driver: sim}
sim: {material: rubber, tubes: 5, seed: 9}
)",
                                             "test");
  EXPECT_TRUE(c.AllSim());
  EXPECT_EQ(c.sim.material, "rubber");
  EXPECT_EQ(c.sim.tubes, 5u);
}

TEST(DevicesConfig, MistakesNameTheKeyAndTheValue) {
  std::string yaml = kRealCell;
  EXPECT_THAT(ErrorOf(yaml + "lidar: {}\n"), HasSubstr("lidar"));
  EXPECT_THAT(ErrorOf(std::string(kRealCell).replace(yaml.find("tool: 3"), 7, "tool: 64")),
              HasSubstr("robot.yaskawa_hses.tool: 0..63, got 64"));
  EXPECT_THAT(ErrorOf(std::string(kRealCell).replace(yaml.find("driver: exec"), 12, "driver: zivid")),
              HasSubstr("scanner.driver: unknown driver 'zivid'"));
  EXPECT_THAT(ErrorOf(std::string(kRealCell).replace(yaml.find("baud: 115200"), 12, "baud: 115201")),
              HasSubstr("gripper.robotiq_2f85_rtu.baud"));
  EXPECT_THAT(ErrorOf(std::string(kRealCell).replace(yaml.find("--out {out}"), 11, "--out x.ply")),
              HasSubstr("has no {out}"));
  // Millimetres where metres belong.
  EXPECT_THAT(
      ErrorOf(std::string(kRealCell).replace(yaml.find("[1.1, -0.2, -0.35]"), 18, "[1100, -200, -350]")),
      HasSubstr("millimetres?"));
  EXPECT_THAT(ErrorOf(std::string(kRealCell).replace(yaml.find("port: 10040"), 11, "port: 70000")),
              HasSubstr("robot.yaskawa_hses.port: a UDP port in 1..65535, got 70000"));
}

TEST(DevicesConfig, ASectionOfADriverNotChosenIsAnError) {
  std::string yaml = kRealCell;
  yaml.replace(yaml.find("driver: yaskawa-hses"), 20, "driver: sim");
  EXPECT_THAT(ErrorOf(yaml), HasSubstr("robot.yaskawa_hses: given, but the driver is sim"));
  EXPECT_THAT(ErrorOf("robot: {driver: yaskawa-hses}\n"), HasSubstr("robot.yaskawa_hses: missing"));
  std::string sim_without_sim_device = std::string(kRealCell) + "sim: {tubes: 3}\n";
  EXPECT_THAT(ErrorOf(sim_without_sim_device), HasSubstr("sim: given, but no device's driver is sim"));
}

}  // namespace
}  // namespace tubepick::devices
