#include "devices/virtual/hses_server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include "core/common/errors.h"
#include "devices/udp_client.h"
#include "devices/virtual/test/scripted_devices.h"
#include "devices/yaskawa_hses.h"

namespace tubepick::devices {
namespace {

using scripted::AngleBetween;
using scripted::Pose;
using scripted::ScriptedRobot;
using ::testing::HasSubstr;
using namespace std::chrono_literals;

/// One wire unit: 1 µm and 0.0001° (with margin for the rounding of both ways).
constexpr double kPositionTol = 2e-6;
constexpr double kAngleTol = 1e-5;
constexpr Timeout kTimeout{5000};

YaskawaHsesParams DriverParams(const HsesServer& server, const Eigen::Isometry3d& X_BaseBin) {
  YaskawaHsesParams params;
  params.host = "127.0.0.1";
  params.port = server.port();
  params.X_BaseBin = X_BaseBin;
  params.poll_interval = Timeout(2);
  return params;
}

/// One raw request and its raw answer (none within 1 s: empty).
std::vector<std::uint8_t> AskRaw(std::uint16_t port, const hses::Request& request) {
  UdpClient udp("127.0.0.1", port, "test");
  const auto deadline = UdpClient::Clock::now() + 1s;
  udp.Send(hses::EncodeRequest(request), deadline);
  std::uint8_t buf[512];
  const auto got = udp.Receive(buf, deadline);
  if (!got) return {};
  return {buf, buf + *got};
}

hses::Answer Ask(std::uint16_t port, const hses::Request& request) {
  const std::vector<std::uint8_t> bytes = AskRaw(port, request);
  const auto answer = hses::DecodeAnswer(bytes);
  if (!answer) throw std::runtime_error("no well-formed answer");
  return *answer;
}

hses::Request MoveRequest(const std::array<std::int32_t, hses::kMoveWords>& words) {
  hses::Request request;
  request.request_id = 7;
  request.command = static_cast<std::uint16_t>(hses::Command::kMoveCartesian);
  request.instance = hses::kStraightAbsolute;
  request.attribute = 1;
  request.service = hses::kServiceSetAll;
  request.data = hses::EncodeWords(words);
  return request;
}

hses::Request StatusRequest(std::uint8_t service = hses::kServiceGetAll, std::uint8_t attribute = 0) {
  hses::Request request;
  request.command = static_cast<std::uint16_t>(hses::Command::kStatusRead);
  request.instance = 1;
  request.attribute = attribute;
  request.service = service;
  return request;
}

std::vector<std::int32_t> StatusWords(std::uint16_t port) {
  return hses::DecodeWords(Ask(port, StatusRequest()).data);
}

TEST(HsesServer, DriverServoOnMoveAndPoseRoundTripThroughXBaseBin) {
  const Eigen::Isometry3d X_BaseBin = Pose(0.6, -0.2, 0.1, 0, 0, 90);
  const Eigen::Isometry3d start = Pose(0.0, 0.0, 0.5, 180, 0, 0);
  ScriptedRobot robot(start);
  std::mutex device_lock;
  HsesServerOptions options;
  options.X_BaseBin = X_BaseBin;
  HsesServer server(robot, device_lock, options);
  YaskawaHses driver(DriverParams(server, X_BaseBin));

  // The position read gives the robot's pose in the bin frame back (base on the wire).
  const Eigen::Isometry3d read0 = driver.CurrentPose(kTimeout);
  EXPECT_LT((read0.translation() - start.translation()).norm(), kPositionTol);
  EXPECT_LT(AngleBetween(read0, start), kAngleTol);

  driver.ServoOn(kTimeout);
  EXPECT_EQ(robot.servo_on_calls(), 1);
  EXPECT_TRUE(server.servo_on());
  EXPECT_EQ(StatusWords(server.port())[1], static_cast<std::int32_t>(hses::kStatus2ServoOn));

  const Eigen::Isometry3d target = Pose(0.12, -0.08, 0.31, 170, 10, -35);
  driver.MoveTo(target, 0.2, kTimeout);
  const std::vector<ScriptedRobot::MoveCall> moves = robot.moves();
  ASSERT_EQ(moves.size(), 1u);
  EXPECT_LT((moves[0].X_BinTcp.translation() - target.translation()).norm(), kPositionTol);
  EXPECT_LT(AngleBetween(moves[0].X_BinTcp, target), kAngleTol);
  EXPECT_NEAR(moves[0].speed, 0.2, 1e-12);  // 2000 × 0.1 mm/s

  const Eigen::Isometry3d read1 = driver.CurrentPose(kTimeout);
  EXPECT_LT((read1.translation() - target.translation()).norm(), kPositionTol);
  EXPECT_LT(AngleBetween(read1, target), kAngleTol);
  EXPECT_FALSE(server.moving());
  // Not running, remote play mode (continuous, play, command remote).
  EXPECT_EQ(StatusWords(server.port())[0], 0xC4);
}

TEST(HsesServer, MoveIsAnsweredAtOnceAndPositionReadsDuringItGiveTheLastPoseWithoutWaiting) {
  const Eigen::Isometry3d start = Pose(0.1, 0.0, 0.4, 180, 0, 0);
  ScriptedRobot robot(start);
  std::mutex device_lock;
  HsesServer server(robot, device_lock);
  YaskawaHses mover(DriverParams(server, Eigen::Isometry3d::Identity()));
  YaskawaHses reader(DriverParams(server, Eigen::Isometry3d::Identity()));
  mover.ServoOn(kTimeout);

  robot.gate.Close();
  const Eigen::Isometry3d target = Pose(-0.1, 0.05, 0.3, 180, 0, 45);
  auto move = std::async(std::launch::async, [&] { mover.MoveTo(target, 0.1, kTimeout); });
  ASSERT_TRUE(robot.gate.AwaitWaiter(2s));
  // The worker holds the device for the whole move.
  EXPECT_FALSE(device_lock.try_lock());
  EXPECT_TRUE(server.moving());
  const std::vector<std::int32_t> status = StatusWords(server.port());
  EXPECT_NE(status[0] & static_cast<std::int32_t>(hses::kStatus1Running), 0);
  const int pose_reads = robot.pose_reads();
  const auto t0 = std::chrono::steady_clock::now();
  const Eigen::Isometry3d during = reader.CurrentPose(Timeout(500));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 200ms);
  EXPECT_LT((during.translation() - start.translation()).norm(), kPositionTol);
  EXPECT_EQ(robot.pose_reads(), pose_reads);  // answered without a device call

  robot.gate.Open();
  move.get();
  const Eigen::Isometry3d after = reader.CurrentPose(kTimeout);
  EXPECT_LT((after.translation() - target.translation()).norm(), kPositionTol);
  EXPECT_LT(AngleBetween(after, target), kAngleTol);
  EXPECT_EQ(StatusWords(server.port())[0] & static_cast<std::int32_t>(hses::kStatus1Running), 0);
}

TEST(HsesServer, RobotFaultMidMoveIsAnAlarmTheDriverReportsUntilServoOnResetsIt) {
  const Eigen::Isometry3d start = Pose(0.0, 0.0, 0.5, 180, 0, 0);
  ScriptedRobot robot(start);
  std::mutex device_lock;
  HsesServer server(robot, device_lock);
  YaskawaHses driver(DriverParams(server, Eigen::Isometry3d::Identity()));
  driver.ServoOn(kTimeout);
  robot.FailMove(1);

  const Eigen::Isometry3d target = Pose(0.2, 0.0, 0.3, 180, 0, 0);
  try {
    driver.MoveTo(target, 0.1, kTimeout);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    // Alarm bit, servo off.
    EXPECT_THAT(e.what(), HasSubstr("alarm/error during move (status data 2 0x00000010)"));
  }
  EXPECT_THAT(server.alarm(), HasSubstr("joint 3 overload"));
  EXPECT_FALSE(server.servo_on());
  // Stopped halfway, and the position read says so.
  const Eigen::Isometry3d stopped = driver.CurrentPose(kTimeout);
  EXPECT_NEAR(stopped.translation().x(), 0.1, kPositionTol);
  EXPECT_NEAR(stopped.translation().z(), 0.4, kPositionTol);

  // The alarm refuses the next move, as a YRC1000 does.
  try {
    driver.MoveTo(target, 0.1, kTimeout);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("status 0x1F, added status 0x2060"));
  }
  EXPECT_EQ(robot.moves().size(), 1u);

  // Servo on resets it (the operator's reset) and the arm moves again.
  driver.ServoOn(kTimeout);
  EXPECT_EQ(server.alarm(), "");
  EXPECT_TRUE(server.servo_on());
  driver.MoveTo(target, 0.1, kTimeout);
  EXPECT_LT((robot.X_BinTcp().translation() - target.translation()).norm(), kPositionTol);
  EXPECT_EQ(robot.moves().size(), 2u);
}

TEST(HsesServer, AnswersEchoTheRequestAndRejectWhatAYrc1000Rejects) {
  ScriptedRobot robot(Pose(0.0, 0.0, 0.5, 180, 0, 0));
  std::mutex device_lock;
  HsesServer server(robot, device_lock);
  const std::uint16_t port = server.port();

  // Header: request id echoed, answer flag, block number 0x80000000, service | 0x80.
  hses::Request status = StatusRequest();
  status.request_id = 0x42;
  const std::vector<std::uint8_t> raw = AskRaw(port, status);
  ASSERT_EQ(raw.size(), hses::kHeaderSize + 8);
  EXPECT_EQ(raw[10], 1);
  EXPECT_EQ(raw[11], 0x42);
  EXPECT_EQ(raw[12], 0x00);
  EXPECT_EQ(raw[15], 0x80);
  EXPECT_EQ(raw[24], 0x81);
  EXPECT_EQ(raw[25], 0x00);
  // Get single, attribute 2: data 2 only (servo off, no alarm).
  const hses::Answer single = Ask(port, StatusRequest(hses::kServiceGetSingle, 2));
  EXPECT_EQ(single.service, 0x8E);
  EXPECT_EQ(hses::DecodeWords(single.data), std::vector<std::int32_t>{0});

  hses::Request unknown;
  unknown.command = 0x99;
  unknown.instance = 1;
  unknown.service = hses::kServiceGetAll;
  const hses::Answer undefined = Ask(port, unknown);
  EXPECT_EQ(undefined.service, 0x81);
  EXPECT_EQ(undefined.status, 0x08);
  EXPECT_EQ(undefined.added_status_size, 0);

  const auto words = hses::MoveData(Pose(0.1, 0.0, 0.3, 180, 0, 0), 0.1);
  // Servo off: the driver's move data itself is refused until servo on.
  hses::Answer answer = Ask(port, MoveRequest(words));
  EXPECT_EQ(answer.request_id, 7);
  EXPECT_EQ(answer.service, 0x82);
  EXPECT_EQ(answer.status, 0x1F);
  EXPECT_EQ(answer.added_status, 0x2070);

  YaskawaHses driver(DriverParams(server, Eigen::Isometry3d::Identity()));
  driver.ServoOn(kTimeout);
  struct Case {
    std::size_t word;
    std::int32_t value;
    std::uint16_t added;
  };
  for (const Case& c : {Case{0, 2, 0xB008},      // robot 2
                        Case{2, 0, 0xB009},      // speed class % (link)
                        Case{2, 2, 0xB009},      // speed class VR
                        Case{3, 0, 0xB009},      // no speed
                        Case{4, 17, 0xB00B},     // robot coordinates
                        Case{4, 19, 0xB00B},     // tool coordinates
                        Case{15, 1, 0xB00D}}) {  // tool 1
    SCOPED_TRACE(::testing::Message() << "word " << c.word << " = " << c.value);
    auto bad = words;
    bad[c.word] = c.value;
    answer = Ask(port, MoveRequest(bad));
    EXPECT_EQ(answer.status, 0x1F);
    EXPECT_EQ(answer.added_status_size, 1);
    EXPECT_EQ(answer.added_status, c.added);
  }
  hses::Request short_move = MoveRequest(words);
  short_move.data.resize(4 * 25);
  EXPECT_EQ(Ask(port, short_move).added_status, 0xB003);
  hses::Request link_move = MoveRequest(words);
  link_move.instance = 1;
  EXPECT_EQ(Ask(port, link_move).added_status, 0xA001);
  hses::Request pulse_read;
  pulse_read.command = static_cast<std::uint16_t>(hses::Command::kPositionRead);
  pulse_read.instance = 1;
  pulse_read.service = hses::kServiceGetAll;
  EXPECT_EQ(Ask(port, pulse_read).added_status, 0xA001);
  EXPECT_TRUE(robot.moves().empty());  // nothing refused reached the robot

  // What the driver sends is accepted.
  answer = Ask(port, MoveRequest(words));
  EXPECT_EQ(answer.status, 0x00);
}

TEST(HsesServer, MovesInAConfiguredUserFrameWithTheConfiguredTool) {
  ScriptedRobot robot(Pose(0.0, 0.0, 0.5, 180, 0, 0));
  std::mutex device_lock;
  HsesServerOptions options;
  options.X_BaseBin = Pose(0.6, -0.2, 0.1, 0, 0, 90);
  options.tool = 2;
  const Eigen::Isometry3d X_BaseUser = Pose(0.5, 0.1, 0.05, 0, 0, -30);
  options.user_frames = {{3, X_BaseUser}};
  HsesServer server(robot, device_lock, options);
  YaskawaHses driver(DriverParams(server, options.X_BaseBin));
  driver.ServoOn(kTimeout);

  const Eigen::Isometry3d X_UserTcp = Pose(0.05, 0.02, 0.3, 180, 0, 10);
  auto words = hses::MoveData(X_UserTcp, 0.1);
  words[4] = 18;  // user coordinates
  words[15] = 2;  // tool 2
  words[16] = 3;  // user frame 3
  EXPECT_EQ(Ask(server.port(), MoveRequest(words)).status, 0x00);
  for (int i = 0; i < 500 && server.moving(); ++i) std::this_thread::sleep_for(2ms);
  const std::vector<ScriptedRobot::MoveCall> moves = robot.moves();
  ASSERT_EQ(moves.size(), 1u);
  const Eigen::Isometry3d X_BinTcp = options.X_BaseBin.inverse() * X_BaseUser * X_UserTcp;
  EXPECT_LT((moves[0].X_BinTcp.translation() - X_BinTcp.translation()).norm(), kPositionTol);
  EXPECT_LT(AngleBetween(moves[0].X_BinTcp, X_BinTcp), kAngleTol);

  // The position read is in base coordinates and names the tool.
  hses::Request read;
  read.command = static_cast<std::uint16_t>(hses::Command::kPositionRead);
  read.instance = hses::kBasePositionInstance;
  read.service = hses::kServiceGetAll;
  const std::vector<std::int32_t> position = hses::DecodeWords(Ask(server.port(), read).data);
  ASSERT_EQ(position.size(), hses::kPositionWords);
  EXPECT_EQ(position[0], 16);
  EXPECT_EQ(position[2], 2);
  EXPECT_NEAR(position[5] * 1e-6, (X_BaseUser * X_UserTcp).translation().x(), kPositionTol);

  words[16] = 4;  // not configured
  EXPECT_EQ(Ask(server.port(), MoveRequest(words)).added_status, 0xB00E);
  words[16] = 3;
  words[15] = 0;  // not the TCP the robot moves
  EXPECT_EQ(Ask(server.port(), MoveRequest(words)).added_status, 0xB00D);
  EXPECT_EQ(robot.moves().size(), 1u);
}

TEST(HsesServer, RobotThatDoesNotAnswerLeavesTheDriverWithoutAnAnswer) {
  ScriptedRobot robot(Pose(0.0, 0.0, 0.5, 180, 0, 0));
  std::mutex device_lock;
  HsesServer server(robot, device_lock);
  YaskawaHses driver(DriverParams(server, Eigen::Isometry3d::Identity()));
  robot.SetPoseTimeout(true);
  EXPECT_THROW(driver.CurrentPose(Timeout(150)), DeviceTimeout);
  robot.SetPoseTimeout(false);
  EXPECT_NEAR(driver.CurrentPose(kTimeout).translation().z(), 0.5, kPositionTol);
}

TEST(HsesServer, BadBindHostIsAnInvalidArgumentNamingIt) {
  ScriptedRobot robot(Eigen::Isometry3d::Identity());
  std::mutex device_lock;
  HsesServerOptions options;
  options.host = "no-such-host.invalid";
  try {
    HsesServer server(robot, device_lock, options);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("no-such-host.invalid"));
  }
}

}  // namespace
}  // namespace tubepick::devices
