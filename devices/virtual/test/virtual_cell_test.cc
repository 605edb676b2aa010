// The simulated cell behind the three protocol servers, driven through the real drivers: what
// `tubepick virtual-cell` serves.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <vector>

#include "devices/ati_netft.h"
#include "devices/robotiq_2f85.h"
#include "devices/sim/sim_cell.h"
#include "devices/sim/test/sim_test_util.h"
#include "devices/virtual/hses_server.h"
#include "devices/virtual/rdt_server.h"
#include "devices/virtual/robotiq_rtu_server.h"
#include "devices/virtual/test/scripted_devices.h"
#include "devices/yaskawa_hses.h"

namespace tubepick::devices {
namespace {

using scripted::AngleBetween;
using scripted::Pose;
using sim::Material;
using sim::SimCell;
using sim::SimCellParams;
using ::testing::HasSubstr;
using namespace std::chrono_literals;

constexpr Timeout kTimeout{std::chrono::seconds(30)};
/// The brief's tolerance of a pose read back: 1 mm, 0.01 rad.
constexpr double kPoseTol = 1e-3;
constexpr double kAngleTol = 0.01;
/// One wire unit of HSES: 1 µm (and 0.0001°), with margin for the rounding both ways.
constexpr double kWireTol = 2e-6;
/// Force within this of the expected weight, N (the sim's noise σ 0.02 N per read, two reads).
constexpr double kForceTol = 0.08;
/// One step of the gripper's gPO: 85 mm / 255.
constexpr double kPositionStep = robotiq::kStroke / 255.0;
constexpr double kG = 9.81;

/// The robot base: 0.9 m beside the bin, 0.3 m below its floor, turned half a turn.
const Eigen::Isometry3d& X_BaseBin() {
  static const Eigen::Isometry3d X = Pose(0.9, 0.0, -0.3, 0, 0, 180);
  return X;
}

/// The three servers on one device lock, and a driver on each.
struct VirtualCell {
  explicit VirtualCell(SimCell& cell)
      : hses(cell.robot(), lock, HsesOptions()),
        rdt(cell.ft_sensor(), lock),
        robotiq(cell.gripper(), lock),
        robot(RobotParams(hses)),
        ft(FtParams(rdt)),
        gripper(GripperParams(robotiq)) {}

  static HsesServerOptions HsesOptions() {
    HsesServerOptions options;
    options.X_BaseBin = X_BaseBin();
    return options;
  }
  static YaskawaHsesParams RobotParams(const HsesServer& server) {
    YaskawaHsesParams params;
    params.host = server.host();
    params.port = server.port();
    params.X_BaseBin = X_BaseBin();
    params.poll_interval = Timeout(2);
    return params;
  }
  static AtiNetFtParams FtParams(const RdtServer& server) {
    AtiNetFtParams params;
    params.host = server.host();
    params.port = server.port();
    return params;
  }
  static Robotiq2F85Params GripperParams(const RobotiqRtuServer& server) {
    Robotiq2F85Params params;
    params.device = server.device_path();
    params.poll_period = Timeout(2);
    return params;
  }

  std::mutex lock;  // the sim's devices share one world
  HsesServer hses;
  RdtServer rdt;
  RobotiqRtuServer robotiq;
  YaskawaHses robot;
  AtiNetFt ft;
  Robotiq2F85 gripper;
};

physics::TubeGeometry StraightTube(double radius, double length) {
  return sim::testing::PolylineTube(
      1, {{-0.5 * length, 0.0, radius}, {0.0, 0.0, radius}, {0.5 * length, 0.0, radius}}, radius);
}

TEST(VirtualCell, SimDevicesThroughTheRealDrivers) {
  SimCell cell(SimCellParams::Thesis(Material::kPvc, 3, 7));
  ASSERT_EQ(cell.TubesInBin(), 3u);
  VirtualCell v(cell);

  // Robot: the pose read back is the sim's (bin frame; base frame on the wire).
  const Eigen::Isometry3d start = v.robot.CurrentPose(kTimeout);
  {
    std::lock_guard lock(v.lock);
    EXPECT_LT((start.translation() - cell.X_BinTcp().translation()).norm(), kWireTol);
    EXPECT_LT(AngleBetween(start, cell.X_BinTcp()), 1e-5);
  }
  v.robot.ServoOn(kTimeout);
  Eigen::Isometry3d target = start;
  target.translation() += Eigen::Vector3d(0.1, -0.05, -0.15);
  target.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix() * start.linear();
  v.robot.MoveTo(target, 0.25, kTimeout);
  const Eigen::Isometry3d reached = v.robot.CurrentPose(kTimeout);
  EXPECT_LT((reached.translation() - target.translation()).norm(), kPoseTol);
  EXPECT_LT(AngleBetween(reached, target), kAngleTol);
  {
    std::lock_guard lock(v.lock);
    EXPECT_LT((cell.X_BinTcp().translation() - target.translation()).norm(), kPoseTol);
    EXPECT_GT(cell.SimulatedSeconds(), 0.8);  // 0.2 m at up to 0.25 m/s, 0.5 m/s² ramps
  }

  // Gripper: activate, open to 45 mm, close on nothing (fully closed), open.
  EXPECT_FALSE(v.gripper.Status(kTimeout).activated);
  v.gripper.Activate(kTimeout);
  EXPECT_TRUE(v.gripper.Status(kTimeout).activated);
  const GripperStatus half = v.gripper.MoveTo(0.045, 0.1, 50.0, kTimeout);
  EXPECT_EQ(half.object, GripperObject::kAtPosition);
  EXPECT_NEAR(half.opening, 0.045, 0.5 * kPositionStep);
  const GripperStatus closed = v.gripper.Close(0.1, 50.0, kTimeout);
  EXPECT_EQ(closed.object, GripperObject::kAtPosition);
  EXPECT_NEAR(closed.opening, 0.0, 1e-12);
  const GripperStatus opened = v.gripper.Open(kTimeout);
  EXPECT_EQ(opened.object, GripperObject::kAtPosition);
  EXPECT_NEAR(opened.opening, robotiq::kStroke, 1e-12);

  // F/T: unbiased, the sensor's offsets (0.4, −0.3, 1.2) N, (0.02, −0.01, 0.005) N·m; biased, ≈ 0.
  const WrenchReading raw = v.ft.Read(kTimeout);
  EXPECT_NEAR(raw.force.x(), 0.4, kForceTol);
  EXPECT_NEAR(raw.force.y(), -0.3, kForceTol);
  EXPECT_NEAR(raw.force.z(), 1.2, kForceTol);
  EXPECT_NEAR(raw.torque.x(), 0.02, 0.01);
  EXPECT_NEAR(raw.torque.y(), -0.01, 0.01);
  EXPECT_NEAR(raw.torque.z(), 0.005, 0.01);
  v.ft.Bias(kTimeout);
  const WrenchReading biased = v.ft.Read(kTimeout);
  EXPECT_LT(biased.force.norm(), kForceTol * std::sqrt(3.0));
  EXPECT_LT(biased.torque.norm(), 0.01);
  EXPECT_GT(biased.sequence, raw.sequence);
}

TEST(VirtualCell, PickATubeReadItsWeightAndSeeItSlipOutThroughTheDrivers) {
  SimCellParams params;
  params.seed = 4;
  const double r = params.cell.tube.radius, m = params.cell.tube.mass;
  SimCell cell(params, {StraightTube(r, 0.5)});
  ASSERT_TRUE(cell.settled());
  VirtualCell v(cell);
  Eigen::Isometry3d X_grasp;
  {
    std::lock_guard lock(v.lock);
    X_grasp = sim::testing::GraspAt(cell.TubesBin()[0], 0.15);
  }

  v.robot.ServoOn(kTimeout);
  v.gripper.Activate(kTimeout);
  v.ft.Bias(kTimeout);
  v.gripper.MoveTo(0.045, 0.1, 50.0, kTimeout);
  v.robot.MoveTo(sim::testing::Raised(X_grasp, 0.10), 0.25, kTimeout);
  v.robot.MoveTo(X_grasp, 0.05, kTimeout);
  const GripperStatus closed = v.gripper.Close(0.05, 50.0, kTimeout);
  EXPECT_EQ(closed.object, GripperObject::kStoppedClosing);
  EXPECT_NEAR(closed.opening, 2 * r, 0.002);
  {
    std::lock_guard lock(v.lock);
    EXPECT_EQ(cell.HeldTubes(), std::vector<std::size_t>{0});
  }
  const WrenchReading before = v.ft.Read(kTimeout);

  const Eigen::Isometry3d X_lifted = sim::testing::Raised(X_grasp, 0.3);
  v.robot.MoveTo(X_lifted, 0.25, kTimeout);
  const Eigen::Isometry3d reached = v.robot.CurrentPose(kTimeout);
  EXPECT_LT((reached.translation() - X_lifted.translation()).norm(), kPoseTol);
  EXPECT_LT(AngleBetween(reached, X_lifted), kAngleTol);
  const WrenchReading after = v.ft.Read(kTimeout);
  // The weight along the upward vertical (sensor axes = TCP axes, z down).
  const Eigen::Vector3d up_Tcp = X_lifted.linear().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(after.force.dot(up_Tcp) - before.force.dot(up_Tcp), -m * kG, kForceTol);
  EXPECT_NEAR(after.force.z(), m * kG, kForceTol);
  EXPECT_EQ(v.gripper.Status(kTimeout).object, GripperObject::kStoppedClosing);

  // The grip gives way on the next motion: the gripper's status says so, not a stale "holding".
  {
    std::lock_guard lock(v.lock);
    cell.ArmSlip(0.2);
  }
  Eigen::Isometry3d X_across = X_lifted;
  X_across.translation().y() += 0.2;
  v.robot.MoveTo(X_across, 0.25, kTimeout);
  const GripperStatus slipped = v.gripper.Status(kTimeout);
  EXPECT_EQ(slipped.object, GripperObject::kAtPosition);
  EXPECT_NEAR(slipped.opening, 2 * r, 0.002);  // the fingers stay
  {
    std::lock_guard lock(v.lock);
    EXPECT_TRUE(cell.HeldTubes().empty());
    EXPECT_EQ(cell.fault_events().slips, 1u);
  }
  EXPECT_NEAR(v.ft.Read(kTimeout).force.z(), 0.0, kForceTol);
}

TEST(VirtualCell, SimRobotAlarmIsADriverFaultUntilServoOn) {
  SimCell cell(SimCellParams::Thesis(Material::kPvc, 3, 7));
  VirtualCell v(cell);
  v.robot.ServoOn(kTimeout);
  const Eigen::Isometry3d start = v.robot.CurrentPose(kTimeout);
  {
    std::lock_guard lock(v.lock);
    cell.ArmRobotAlarm(0.2);
  }
  Eigen::Isometry3d lower = start;
  lower.translation().z() -= 0.3;
  try {
    v.robot.MoveTo(lower, 0.25, kTimeout);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("alarm/error during move"));
  }
  EXPECT_THAT(v.hses.alarm(), HasSubstr("alarm 4100"));
  const Eigen::Isometry3d stopped = v.robot.CurrentPose(kTimeout);
  EXPECT_GT(start.translation().z() - stopped.translation().z(), 0.005);  // stopped partway
  EXPECT_LT(start.translation().z() - stopped.translation().z(), 0.1);

  v.robot.ServoOn(kTimeout);
  EXPECT_EQ(v.hses.alarm(), "");
  v.robot.MoveTo(start, 0.25, kTimeout);
  EXPECT_LT((v.robot.CurrentPose(kTimeout).translation() - start.translation()).norm(), kPoseTol);
}

}  // namespace
}  // namespace tubepick::devices
