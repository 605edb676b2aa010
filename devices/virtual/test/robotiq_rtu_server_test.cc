#include "devices/virtual/robotiq_rtu_server.h"

#include <modbus/modbus.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <mutex>
#include <thread>

#include "devices/robotiq_2f85.h"
#include "devices/virtual/test/scripted_devices.h"

namespace tubepick::devices {
namespace {

using scripted::ScriptedGripper;
using ::testing::HasSubstr;
using namespace std::chrono_literals;

constexpr Timeout kTimeout{3000};
/// One step of gPO: 85 mm / 255.
constexpr double kPositionStep = robotiq::kStroke / 255.0;

Robotiq2F85Params DriverParams(const RobotiqRtuServer& server) {
  Robotiq2F85Params params;
  params.device = server.device_path();
  params.poll_period = std::chrono::milliseconds(2);
  // A real gripper answers within the driver's 200 ms; the virtual one is a thread on a pty that a
  // loaded 2-core CI machine can keep waiting longer (one clean-clone run lost a write at 200 ms).
  params.response_timeout = std::chrono::milliseconds(1000);
  return params;
}

/// A bare Modbus RTU master on the server's terminal, for what the driver does not show.
class Master {
 public:
  explicit Master(const std::string& device) {
    ctx_ = modbus_new_rtu(device.c_str(), robotiq::kDefaultBaud, 'N', 8, 1);
    if (ctx_ == nullptr || modbus_set_slave(ctx_, robotiq::kDefaultSlaveId) != 0 ||
        modbus_connect(ctx_) != 0) {
      throw std::runtime_error("cannot open " + device);
    }
    modbus_set_response_timeout(ctx_, 0, 500000);
  }
  ~Master() {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
  void Write(std::uint8_t action, std::uint8_t position, std::uint8_t speed, std::uint8_t force) {
    const auto regs = robotiq::EncodeRequest(action, position, speed, force);
    if (modbus_write_registers(ctx_, robotiq::kOutputAddress, robotiq::kRegisterCount, regs.data()) != 3) {
      throw std::runtime_error(std::string("write: ") + modbus_strerror(errno));
    }
  }
  robotiq::InputState Read() {
    std::array<std::uint16_t, robotiq::kRegisterCount> regs{};
    if (modbus_read_input_registers(ctx_, robotiq::kInputAddress, robotiq::kRegisterCount, regs.data()) !=
        3) {
      throw std::runtime_error(std::string("read: ") + modbus_strerror(errno));
    }
    return robotiq::DecodeInput(regs);
  }
  modbus_t* ctx() { return ctx_; }

 private:
  modbus_t* ctx_ = nullptr;
};

TEST(RobotiqRtuServer, DriverActivatesMovesClosesOnATubeAndSeesItSlipOut) {
  ScriptedGripper gripper;
  gripper.SetObjectWidth(0.025);
  std::mutex device_lock;
  RobotiqRtuServer server(gripper, device_lock);
  Robotiq2F85 driver(DriverParams(server));

  EXPECT_FALSE(driver.Status(kTimeout).activated);
  driver.Activate(kTimeout);
  EXPECT_EQ(gripper.activations(), 1);
  EXPECT_TRUE(driver.Status(kTimeout).activated);

  // MoveTo: opening, speed and force as the registers carry them.
  const GripperStatus moved = driver.MoveTo(0.045, 0.1, 50.0, kTimeout);
  std::vector<ScriptedGripper::MotionCall> motions = gripper.motions();
  ASSERT_EQ(motions.size(), 1u);
  EXPECT_FALSE(motions[0].close);
  EXPECT_DOUBLE_EQ(motions[0].opening, robotiq::PositionToOpening(robotiq::OpeningToPosition(0.045)));
  EXPECT_NEAR(motions[0].opening, 0.045, 0.5 * kPositionStep);
  EXPECT_DOUBLE_EQ(motions[0].speed, robotiq::ByteToSpeed(robotiq::SpeedToByte(0.1)));
  EXPECT_DOUBLE_EQ(motions[0].force, robotiq::ByteToForce(robotiq::ForceToByte(50.0)));
  EXPECT_EQ(moved.object, GripperObject::kAtPosition);
  EXPECT_NEAR(moved.opening, 0.045, 0.5 * kPositionStep);
  EXPECT_EQ(moved.fault, 0);

  // Close (rPR 255): Gripper::Close, which stops on the 25 mm tube.
  const GripperStatus closed = driver.Close(0.05, 100.0, kTimeout);
  motions = gripper.motions();
  ASSERT_EQ(motions.size(), 2u);
  EXPECT_TRUE(motions[1].close);
  EXPECT_NEAR(motions[1].speed, 0.05, 0.5 * (robotiq::kMaxSpeed - robotiq::kMinSpeed) / 255.0);
  EXPECT_NEAR(motions[1].force, 100.0, 0.5 * (robotiq::kMaxForce - robotiq::kMinForce) / 255.0);
  EXPECT_EQ(closed.object, GripperObject::kStoppedClosing);
  EXPECT_NEAR(closed.opening, 0.025, 0.5 * kPositionStep);
  EXPECT_EQ(driver.Status(kTimeout).object, GripperObject::kStoppedClosing);

  // The tube slips out: a status read asks the gripper, not the last motion's result.
  gripper.DropObject();
  const GripperStatus slipped = driver.Status(kTimeout);
  EXPECT_EQ(slipped.object, GripperObject::kAtPosition);
  EXPECT_NEAR(slipped.opening, 0.025, 0.5 * kPositionStep);

  // Open: the driver's full stroke at full speed, least force.
  const GripperStatus opened = driver.Open(kTimeout);
  motions = gripper.motions();
  ASSERT_EQ(motions.size(), 3u);
  EXPECT_FALSE(motions[2].close);
  EXPECT_DOUBLE_EQ(motions[2].opening, robotiq::kStroke);
  EXPECT_DOUBLE_EQ(motions[2].speed, robotiq::kMaxSpeed);
  EXPECT_DOUBLE_EQ(motions[2].force, robotiq::kMinForce);
  EXPECT_EQ(opened.object, GripperObject::kAtPosition);
  EXPECT_DOUBLE_EQ(opened.opening, robotiq::kStroke);
}

TEST(RobotiqRtuServer, ActivationAndMotionReportBusyUntilTheGripperIsDone) {
  ScriptedGripper gripper;
  std::mutex device_lock;
  RobotiqRtuServer server(gripper, device_lock);
  Master master(server.device_path());

  gripper.activation_gate.Close();
  master.Write(robotiq::kRact, 0, 0, 0);
  ASSERT_TRUE(gripper.activation_gate.AwaitWaiter(2s));
  robotiq::InputState s = master.Read();
  EXPECT_TRUE(s.gact);
  EXPECT_EQ(s.gsta, 1);
  EXPECT_FALSE(device_lock.try_lock());  // Activate runs holding the device lock
  gripper.activation_gate.Open();
  for (int i = 0; i < 200 && s.gsta != 3; ++i) {
    std::this_thread::sleep_for(2ms);
    s = master.Read();
  }
  EXPECT_EQ(s.gsta, 3);
  EXPECT_EQ(s.gobj, 3);

  gripper.motion_gate.Close();
  master.Write(robotiq::kRact | robotiq::kRgto, 120, 255, 0);
  ASSERT_TRUE(gripper.motion_gate.AwaitWaiter(2s));
  s = master.Read();
  EXPECT_TRUE(s.ggto);
  EXPECT_EQ(s.gobj, 0);  // moving
  EXPECT_EQ(s.position_echo, 120);
  EXPECT_EQ(s.position, 0);  // still where it was: fully open
  gripper.motion_gate.Open();
  for (int i = 0; i < 200 && s.gobj == 0; ++i) {
    std::this_thread::sleep_for(2ms);
    s = master.Read();
  }
  EXPECT_EQ(s.gobj, 3);
  EXPECT_EQ(s.position, 120);

  // rACT cleared: reset.
  master.Write(0, 0, 0, 0);
  s = master.Read();
  EXPECT_FALSE(s.gact);
  EXPECT_EQ(s.gsta, 0);
}

TEST(RobotiqRtuServer, GripperFaultIsLatchedInGfltUntilReactivation) {
  ScriptedGripper gripper;
  std::mutex device_lock;
  RobotiqRtuServer server(gripper, device_lock);
  Robotiq2F85 driver(DriverParams(server));
  driver.Activate(kTimeout);

  gripper.FailNextMotion();
  try {
    driver.MoveTo(0.03, 0.1, 50.0, kTimeout);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("gripper fault 0x0E: overcurrent triggered"));
  }
  EXPECT_THAT(server.fault(), HasSubstr("finger motor stalled"));
  const GripperStatus status = driver.Status(kTimeout);
  EXPECT_EQ(status.fault, 0x0E);
  EXPECT_EQ(status.fault_text, "overcurrent triggered");
  EXPECT_TRUE(status.activated);

  // Latched: no motion starts until rACT is cleared and set again.
  EXPECT_THROW(driver.MoveTo(0.03, 0.1, 50.0, kTimeout), DeviceFault);
  EXPECT_EQ(gripper.motions().size(), 1u);
  driver.Activate(kTimeout);  // clears rACT, then sets it
  EXPECT_EQ(driver.Status(kTimeout).fault, 0);
  EXPECT_EQ(server.fault(), "");
  const GripperStatus moved = driver.MoveTo(0.03, 0.1, 50.0, kTimeout);
  EXPECT_NEAR(moved.opening, 0.03, 0.5 * kPositionStep);
  EXPECT_EQ(gripper.motions().size(), 2u);
  EXPECT_EQ(gripper.activations(), 2);
}

TEST(RobotiqRtuServer, StatusThatFailsIsNoAnswerOrAnExceptionAnswer) {
  ScriptedGripper gripper;
  std::mutex device_lock;
  RobotiqRtuServer server(gripper, device_lock);
  Robotiq2F85 driver(DriverParams(server));
  driver.Activate(kTimeout);

  gripper.SetStatusError(1);
  EXPECT_THROW(driver.Status(kTimeout), DeviceTimeout);
  gripper.SetStatusError(2);
  try {
    driver.Status(kTimeout);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("status read failed"));
  }
  gripper.SetStatusError(0);
  EXPECT_TRUE(driver.Status(kTimeout).activated);
}

TEST(RobotiqRtuServer, StatusReadsFallBackOnTheLastStateWhileAnotherDeviceHoldsTheLock) {
  ScriptedGripper gripper;
  std::mutex device_lock;
  RobotiqRtuServer server(gripper, device_lock);
  Robotiq2F85 driver(DriverParams(server));
  driver.Activate(kTimeout);
  const int reads = gripper.status_reads();
  std::lock_guard held(device_lock);
  const GripperStatus status = driver.Status(kTimeout);
  EXPECT_TRUE(status.activated);
  EXPECT_DOUBLE_EQ(status.opening, robotiq::kStroke);
  EXPECT_EQ(gripper.status_reads(), reads);
}

TEST(RobotiqRtuServer, OtherRegistersAreIllegalDataAddresses) {
  ScriptedGripper gripper;
  std::mutex device_lock;
  RobotiqRtuServer server(gripper, device_lock);
  Master master(server.device_path());
  std::uint16_t regs[3] = {};
  EXPECT_EQ(modbus_read_input_registers(master.ctx(), 0x0100, 3, regs), -1);
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_write_registers(master.ctx(), 0x03E9, 3, regs), -1);
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(master.Read().gsta, 0);  // the refused write did nothing
  EXPECT_EQ(gripper.activations(), 0);
}

}  // namespace
}  // namespace tubepick::devices
