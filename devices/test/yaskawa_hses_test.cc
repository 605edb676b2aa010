#include "devices/yaskawa_hses.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <thread>

#include "devices/testing/hses_fake.h"

namespace tubepick::devices {
namespace {

using ::testing::ElementsAre;
using ::testing::ElementsAreArray;
using ::testing::HasSubstr;
using namespace std::chrono_literals;

constexpr double kDeg = std::numbers::pi / 180.0;

YaskawaHsesParams LoopbackParams(const HsesFake& fake) {
  YaskawaHsesParams params;
  params.host = "127.0.0.1";
  params.port = fake.port();
  params.poll_interval = Timeout(5);
  return params;
}

Eigen::Isometry3d Pose(double x, double y, double z, double rx_deg, double ry_deg, double rz_deg) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(x, y, z);
  X.linear() = (Eigen::AngleAxisd(rz_deg * kDeg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(ry_deg * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(rx_deg * kDeg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return X;
}

TEST(HsesCodec, RequestHeaderByteByByte) {
  hses::Request request;
  request.request_id = 0x05;
  request.command = 0x8A;
  request.instance = 0x0102;
  request.attribute = 0x01;
  request.service = 0x02;
  request.data = {0xAA, 0xBB, 0xCC, 0xDD};
  EXPECT_THAT(hses::EncodeRequest(request), ElementsAre('Y', 'E', 'R', 'C',  // identifier
                                                        0x20, 0x00,          // header size
                                                        0x04, 0x00,          // data size
                                                        0x03,                // reserve 1
                                                        0x01,  // processing division: robot control
                                                        0x00,  // ACK: request
                                                        0x05,  // request ID
                                                        0x00, 0x00, 0x00, 0x00,  // block number
                                                        '9', '9', '9', '9', '9', '9', '9', '9',  // reserve 2
                                                        0x8A, 0x00,                              // command
                                                        0x02, 0x01,                              // instance
                                                        0x01,                                    // attribute
                                                        0x02,                                    // service
                                                        0x00, 0x00,                              // padding
                                                        0xAA, 0xBB, 0xCC, 0xDD));
  const auto back = hses::DecodeRequest(hses::EncodeRequest(request));
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->command, 0x8A);
  EXPECT_EQ(back->instance, 0x0102);
  EXPECT_EQ(back->request_id, 0x05);
  EXPECT_THAT(back->data, ElementsAre(0xAA, 0xBB, 0xCC, 0xDD));
}

TEST(HsesCodec, AnswerHeaderByteByByte) {
  hses::Answer answer;
  answer.request_id = 0x07;
  answer.service = 0x82;
  answer.status = 0x1F;
  answer.added_status_size = 1;
  answer.added_status = 0xA001;
  const auto bytes = hses::EncodeAnswer(answer);
  ASSERT_EQ(bytes.size(), 32u);
  EXPECT_EQ(bytes[10], 0x01);  // ACK: answer
  EXPECT_EQ(bytes[11], 0x07);
  EXPECT_THAT(std::vector<std::uint8_t>(bytes.begin() + 12, bytes.begin() + 16), ElementsAre(0, 0, 0, 0x80));
  EXPECT_THAT(std::vector<std::uint8_t>(bytes.begin() + 24, bytes.end()),
              ElementsAre(0x82, 0x1F, 0x01, 0x00, 0x01, 0xA0, 0x00, 0x00));
  const auto back = hses::DecodeAnswer(bytes);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->status, 0x1F);
  EXPECT_EQ(back->added_status, 0xA001);
  EXPECT_FALSE(hses::DecodeRequest(bytes).has_value());  // an answer is not a request
  EXPECT_FALSE(hses::DecodeAnswer(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + 31)).has_value());
}

TEST(HsesCodec, WordsAreLittleEndianSigned) {
  const std::int32_t words[2] = {-2, 0x01020304};
  EXPECT_THAT(hses::EncodeWords(words), ElementsAre(0xFE, 0xFF, 0xFF, 0xFF, 0x04, 0x03, 0x02, 0x01));
  EXPECT_THAT(hses::DecodeWords(hses::EncodeWords(words)), ElementsAre(-2, 0x01020304));
}

TEST(HsesCodec, MoveDataUnitsAreMicrometresAndTenThousandthsOfADegree) {
  const auto words = hses::MoveData(Pose(0.5, -0.25, 0.1234567, 180.0, 10.5, -90.0), 0.25);
  EXPECT_EQ(words[0], 1);       // robot 1
  EXPECT_EQ(words[1], 0);       // no station
  EXPECT_EQ(words[2], 1);       // speed class V
  EXPECT_EQ(words[3], 2500);    // 0.25 m/s = 2500 × 0.1 mm/s
  EXPECT_EQ(words[4], 16);      // base coordinates
  EXPECT_EQ(words[5], 500000);  // µm
  EXPECT_EQ(words[6], -250000);
  EXPECT_EQ(words[7], 123457);
  // Rx 180° may come back as ±180°; the other two then differ too, so compare rotations.
  const Eigen::Isometry3d back = hses::PoseFromWords(std::span<const std::int32_t, 6>(words.data() + 5, 6));
  EXPECT_TRUE(back.isApprox(Pose(0.5, -0.25, 0.123457, 180.0, 10.5, -90.0), 1e-6));
  for (std::size_t i = 11; i < words.size(); ++i) {
    EXPECT_EQ(words[i], 0) << "word " << i;
  }
  const auto plain = hses::PoseToWords(Pose(0.0, 0.0, 0.0, 12.3456, -7.5, 45.0));
  EXPECT_THAT(plain, ElementsAre(0, 0, 0, 123456, -75000, 450000));
  EXPECT_THAT(hses::PoseToWords(Pose(0.0, 0.0, 0.0, -30.0, 20.0, -135.0)),
              ElementsAre(0, 0, 0, -300000, 200000, -1350000));
}

TEST(YaskawaHses, ServoOnReachesTheFake) {
  HsesFake fake;
  YaskawaHses robot(LoopbackParams(fake));
  EXPECT_FALSE(fake.servo_on());
  robot.ServoOn(500ms);
  EXPECT_TRUE(fake.servo_on());
  const auto requests = fake.requests();
  ASSERT_EQ(requests.size(), 1u);
  EXPECT_EQ(requests[0].command, 0x83);
  EXPECT_EQ(requests[0].instance, 2);
  EXPECT_EQ(requests[0].service, 0x10);
  EXPECT_THAT(requests[0].data, ElementsAre(1, 0, 0, 0));
}

TEST(YaskawaHses, MoveThenPollCompletesAtTheTarget) {
  HsesFake fake(60ms);
  YaskawaHses robot(LoopbackParams(fake));
  robot.ServoOn(500ms);
  const auto start = std::chrono::steady_clock::now();
  robot.MoveTo(Pose(0.4, 0.1, 0.3, 180.0, 0.0, 0.0), 0.2, 2000ms);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 60ms);
  EXPECT_GE(fake.status_reads(), 2);
  EXPECT_THAT(fake.position(), ElementsAreArray(hses::PoseToWords(Pose(0.4, 0.1, 0.3, 180.0, 0.0, 0.0))));
  ASSERT_EQ(fake.moves().size(), 1u);
  EXPECT_EQ(fake.moves()[0][3], 2000);
}

TEST(YaskawaHses, PositionRoundTripAppliesXBaseBin) {
  HsesFake fake(10ms);
  YaskawaHsesParams params = LoopbackParams(fake);
  params.X_BaseBin = Pose(0.6, -0.2, 0.05, 0.0, 0.0, 90.0);
  YaskawaHses robot(params);
  robot.ServoOn(500ms);

  const Eigen::Isometry3d X_BinTcp = Pose(0.1, 0.05, 0.2, 180.0, 0.0, 30.0);
  robot.MoveTo(X_BinTcp, 0.0, 2000ms);  // default speed
  // The fake holds the base-frame pose: bin (0.1, 0.05, 0.2) rotated 90° about z, plus offset.
  const auto words = fake.position();
  EXPECT_NEAR(words[0], 550000, 1);
  EXPECT_NEAR(words[1], -100000, 1);
  EXPECT_NEAR(words[2], 250000, 1);
  EXPECT_EQ(fake.moves().at(0)[3], 1000);  // default 0.1 m/s

  EXPECT_TRUE(robot.CurrentPose(500ms).isApprox(X_BinTcp, 1e-6));
  fake.SetPosition({600000, -200000, 50000, 0, 0, 900000});  // the bin origin, bin axes
  EXPECT_TRUE(robot.CurrentPose(500ms).isApprox(Eigen::Isometry3d::Identity(), 1e-6));
}

TEST(YaskawaHses, MoveThroughVisitsRelativeWaypoints) {
  HsesFake fake(5ms);
  YaskawaHses robot(LoopbackParams(fake));
  robot.ServoOn(500ms);
  fake.SetPosition({100000, 0, 200000, 1800000, 0, 0});
  robot.MoveThrough(
      {Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.01, 0.0), Eigen::Vector3d(0.0, 0.01, -0.02)}, 0.05,
      2000ms);
  const auto moves = fake.moves();
  ASSERT_EQ(moves.size(), 3u);
  EXPECT_EQ(moves[1][6], 10000);
  EXPECT_EQ(moves[2][7], 180000);
  EXPECT_THAT(fake.position(), ElementsAre(100000, 10000, 180000, ::testing::_, 0, 0));
}

TEST(YaskawaHses, ErrorStatusIsADeviceFaultNamingIt) {
  HsesFake fake;
  YaskawaHses robot(LoopbackParams(fake));
  fake.SetErrorStatus(0x1F, 0xA001);
  try {
    robot.ServoOn(500ms);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("0x1F"));
    EXPECT_THAT(e.what(), HasSubstr("0xA001"));
    EXPECT_THAT(e.what(), HasSubstr("0x83"));
  }
  fake.SetErrorStatus(0, 0);
  // Servo off: the fake refuses the move.
  EXPECT_THROW(robot.MoveTo(Pose(0.1, 0.0, 0.1, 0, 0, 0), 0.1, 500ms), DeviceFault);
}

TEST(YaskawaHses, SilenceIsADeviceTimeout) {
  HsesFake fake;
  YaskawaHses robot(LoopbackParams(fake));
  fake.SetSilent(true);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(robot.CurrentPose(100ms), DeviceTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 100ms);
  EXPECT_THROW(robot.ServoOn(50ms), DeviceTimeout);
  fake.SetSilent(false);
  robot.ServoOn(500ms);  // recovers; the late answers are not mistaken for this one
  EXPECT_TRUE(fake.servo_on());
}

TEST(YaskawaHses, MoveLongerThanTheTimeoutIsADeviceTimeout) {
  HsesFake fake(1000ms);
  YaskawaHses robot(LoopbackParams(fake));
  robot.ServoOn(500ms);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(robot.MoveTo(Pose(0.1, 0.0, 0.1, 0, 0, 0), 0.1, 100ms), DeviceTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 100ms);
}

TEST(YaskawaHses, MovesInTheConfiguredToolAndUserFrame) {
  HsesFake fake(10ms);
  YaskawaHsesParams params = LoopbackParams(fake);
  params.tool = 3;
  params.user_frame = 2;
  params.X_BaseBin = Pose(1.0, 0.0, 0.0, 0, 0, 0);
  params.X_BaseUser = Pose(1.0, 0.5, 0.0, 0, 0, 90);  // user frame 2: 0.5 m to the side, turned 90°
  YaskawaHses robot(params);
  robot.ServoOn(500ms);
  robot.MoveTo(Pose(0.0, 0.0, 0.3, 180, 0, 0), 0.1, 2000ms);
  ASSERT_EQ(fake.moves().size(), 1u);
  const auto& words = fake.moves()[0];
  EXPECT_EQ(words[4], hses::kCoordinateUser);
  EXPECT_EQ(words[15], 3) << "tool number";
  EXPECT_EQ(words[16], 2) << "user frame number";
  // The bin origin is 0.5 m along -y of the base from the user origin: +0.5 m along the user's x
  // (turned 90° about z) would be base +y, so the bin lies at user x = -0.5, y = 0.
  EXPECT_EQ(words[5], -500000);
  EXPECT_EQ(words[6], 0);
  EXPECT_EQ(words[7], 300000);
}

TEST(YaskawaHses, StatusReportsServoAndAlarmBits) {
  HsesFake fake;
  YaskawaHses robot(LoopbackParams(fake));
  std::optional<RobotStatus> status = robot.Status(500ms);
  ASSERT_TRUE(status);
  EXPECT_FALSE(status->servo_on);
  robot.ServoOn(500ms);
  status = robot.Status(500ms);
  ASSERT_TRUE(status);
  EXPECT_TRUE(status->servo_on);
  EXPECT_FALSE(status->alarm);
  EXPECT_THAT(status->detail, HasSubstr("data 2 0x"));
}

TEST(YaskawaHses, AnUnansweredReadIsSentAgainWithinTheCallsTimeout) {
  HsesFake fake;
  YaskawaHsesParams params = LoopbackParams(fake);
  params.request_timeout = 100ms;
  YaskawaHses robot(params);
  fake.SetSilent(true);
  std::thread wake([&] {
    std::this_thread::sleep_for(250ms);
    fake.SetSilent(false);
  });
  EXPECT_NO_THROW(robot.CurrentPose(2000ms));
  wake.join();
  EXPECT_GE(fake.requests().size(), 3u) << "the first reads went unanswered and were sent again";
}

}  // namespace
}  // namespace tubepick::devices
