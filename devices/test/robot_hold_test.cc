#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "devices/robot.h"

namespace tubepick::devices {
namespace {

using Clock = std::chrono::steady_clock;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

/// A robot driver that keeps Robot::Hold's default (a real arm holding its pose).
class StillRobot final : public Robot {
 public:
  void MoveTo(const Eigen::Isometry3d&, double, Timeout) override { ++motions; }
  void MoveThrough(const std::vector<Eigen::Vector3d>&, double, Timeout) override { ++motions; }
  Eigen::Isometry3d CurrentPose(Timeout) override { return Eigen::Isometry3d::Identity(); }
  void ServoOn(Timeout) override {}
  RobotLimits Limits() const override { return {}; }
  int motions = 0;
};

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

TEST(RobotHold, TheDefaultWaitsOnTheWallClockWithoutMoving) {
  StillRobot robot;
  const Clock::time_point start = Clock::now();
  robot.Hold(0.05, Timeout(1000));
  EXPECT_GE(SecondsSince(start), 0.05);
  robot.Hold(0.0, Timeout(1000));
  EXPECT_EQ(robot.motions, 0);
}

TEST(RobotHold, ALongerHoldThanTheTimeoutIsATimeoutAfterWaitingIt) {
  StillRobot robot;
  const Clock::time_point start = Clock::now();
  EXPECT_THAT([&] { robot.Hold(5.0, Timeout(30)); },
              ThrowsMessage<DeviceTimeout>(HasSubstr("a hold of 5.00 s exceeds the timeout of 0.030 s")));
  const double waited = SecondsSince(start);
  EXPECT_GE(waited, 0.03);
  EXPECT_LT(waited, 5.0);
}

TEST(RobotHold, ANegativeOrNonFiniteHoldIsAFaultNamingIt) {
  StillRobot robot;
  EXPECT_THAT([&] { robot.Hold(-0.5, Timeout(1000)); }, ThrowsMessage<DeviceFault>(HasSubstr("-0.5 s")));
  EXPECT_THROW(robot.Hold(std::nan(""), Timeout(1000)), DeviceFault);
  EXPECT_THROW(robot.Hold(INFINITY, Timeout(1000)), DeviceFault);
}

}  // namespace
}  // namespace tubepick::devices
