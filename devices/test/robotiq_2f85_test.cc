#include "devices/robotiq_2f85.h"

#include <gtest/gtest.h>

#include <chrono>
#include <regex>
#include <string>

#include "devices/testing/robotiq_fake.h"

namespace tubepick::devices {
namespace {

using namespace std::chrono_literals;
namespace rq = robotiq;

Robotiq2F85Params ParamsFor(const RobotiqFake& fake) {
  Robotiq2F85Params p;
  p.device = fake.device_path();
  p.response_timeout = 100ms;
  return p;
}

TEST(Robotiq2F85Encoding, PositionMapsOpeningLinearlyAndClamps) {
  EXPECT_EQ(rq::OpeningToPosition(0.085), 0);
  EXPECT_EQ(rq::OpeningToPosition(0.0), 255);
  EXPECT_EQ(rq::OpeningToPosition(0.0425), 128);  // 127.5 rounds up
  EXPECT_EQ(rq::OpeningToPosition(1.0), 0);
  EXPECT_EQ(rq::OpeningToPosition(-0.01), 255);
  EXPECT_NEAR(rq::PositionToOpening(0), 0.085, 1e-12);
  EXPECT_NEAR(rq::PositionToOpening(255), 0.0, 1e-12);
  for (int p = 0; p <= 255; ++p) {
    EXPECT_EQ(rq::OpeningToPosition(rq::PositionToOpening(static_cast<std::uint8_t>(p))), p);
  }
}

TEST(Robotiq2F85Encoding, SpeedAndForceMapLinearlyAndClamp) {
  EXPECT_EQ(rq::SpeedToByte(0.020), 0);
  EXPECT_EQ(rq::SpeedToByte(0.150), 255);
  EXPECT_EQ(rq::SpeedToByte(0.085), 128);  // midpoint 127.5
  EXPECT_EQ(rq::SpeedToByte(0.001), 0);
  EXPECT_EQ(rq::SpeedToByte(1.0), 255);
  EXPECT_EQ(rq::ForceToByte(20.0), 0);
  EXPECT_EQ(rq::ForceToByte(235.0), 255);
  EXPECT_EQ(rq::ForceToByte(127.5), 128);
  EXPECT_EQ(rq::ForceToByte(0.0), 0);
  EXPECT_EQ(rq::ForceToByte(1000.0), 255);
  EXPECT_NEAR(rq::ByteToForce(rq::ForceToByte(100.0)), 100.0, 0.5);
}

TEST(Robotiq2F85Encoding, RequestRegistersMatchTheManualsExample) {
  // Manual: close at full speed and force = 09 10 03E8 0003 06 | 09 00 00 FF FF FF
  const auto regs = rq::EncodeRequest(rq::kRact | rq::kRgto, 0xFF, 0xFF, 0xFF);
  EXPECT_EQ(regs[0], 0x0900);
  EXPECT_EQ(regs[1], 0x00FF);
  EXPECT_EQ(regs[2], 0xFFFF);
  const auto r2 = rq::EncodeRequest(rq::kRact, 0x12, 0x34, 0x56);
  EXPECT_EQ(r2[0], 0x0100);
  EXPECT_EQ(r2[1], 0x0012);
  EXPECT_EQ(r2[2], 0x3456);
}

TEST(Robotiq2F85Encoding, InputRegistersDecode) {
  // Manual: completed close on object = B9 00 00 FF BD 00 (gOBJ 2, gSTA 3, gGTO, gACT).
  const auto s = rq::DecodeInput({0xB900, 0x00FF, 0xBD00});
  EXPECT_TRUE(s.gact);
  EXPECT_TRUE(s.ggto);
  EXPECT_EQ(s.gsta, 3);
  EXPECT_EQ(s.gobj, 2);
  EXPECT_EQ(s.gflt, 0);
  EXPECT_EQ(s.position_echo, 0xFF);
  EXPECT_EQ(s.position, 0xBD);
  const auto f = rq::DecodeInput({0x3100, 0x0E00, 0x0000});
  EXPECT_EQ(f.gflt, 0x0E);
  EXPECT_EQ(f.gsta, 3);
  EXPECT_EQ(f.gobj, 0);
  const auto round = rq::DecodeInput(rq::EncodeInput(s));
  EXPECT_EQ(round.gobj, 2);
  EXPECT_EQ(round.position, 0xBD);
  EXPECT_NE(rq::FaultText(0x0E).find("overcurrent"), std::string::npos);
}

TEST(Robotiq2F85, ActivatesOverModbusRtuOnAPty) {
  RobotiqFake fake;
  Robotiq2F85 gripper(ParamsFor(fake));
  EXPECT_FALSE(gripper.Status(1s).activated);
  gripper.Activate(2s);
  const auto st = gripper.Status(1s);
  EXPECT_TRUE(st.activated);
  EXPECT_EQ(st.fault, 0);
  EXPECT_NEAR(st.opening, 0.085, 1e-9);
  EXPECT_GT(fake.requests_served(), 3);  // real RTU frames went through the pty
}

TEST(Robotiq2F85, ClosesOnAnObjectThenOpens) {
  RobotiqFake fake;
  fake.SetObjectWidth(0.016);  // a 16 mm tube
  Robotiq2F85 gripper(ParamsFor(fake));
  gripper.Activate(2s);
  const auto closed = gripper.Close(0.15, 50.0, 5s);
  EXPECT_EQ(closed.object, GripperObject::kStoppedClosing);
  EXPECT_NEAR(closed.opening, 0.016, 0.001);
  EXPECT_TRUE(closed.activated);
  const auto opened = gripper.Open(5s);
  EXPECT_EQ(opened.object, GripperObject::kAtPosition);
  EXPECT_NEAR(opened.opening, 0.085, 1e-9);
}

TEST(Robotiq2F85, MoveToWithoutObjectReachesPosition) {
  RobotiqFake fake;
  Robotiq2F85 gripper(ParamsFor(fake));
  gripper.Activate(2s);
  const auto st = gripper.MoveTo(0.040, 0.15, 100.0, 5s);
  EXPECT_EQ(st.object, GripperObject::kAtPosition);
  EXPECT_NEAR(st.opening, 0.040, 0.085 / 255.0);
}

TEST(Robotiq2F85, FaultThrowsDeviceFaultNamingTheCode) {
  RobotiqFake fake;
  Robotiq2F85 gripper(ParamsFor(fake));
  gripper.Activate(2s);
  fake.SetFault(0x0E);
  try {
    gripper.Close(0.1, 50.0, 2s);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("0x0E"), std::string::npos) << what;
    EXPECT_NE(what.find("overcurrent"), std::string::npos) << what;
  }
  const auto st = gripper.Status(1s);  // Status reports rather than throws
  EXPECT_EQ(st.fault, 0x0E);
  // Reactivation (rACT cleared) resets the fault.
  gripper.Activate(2s);
  EXPECT_EQ(gripper.Status(1s).fault, 0);
}

TEST(Robotiq2F85, NoAnswerThrowsDeviceTimeout) {
  RobotiqFake fake;
  Robotiq2F85 gripper(ParamsFor(fake));
  fake.SetMute(true);
  EXPECT_THROW(gripper.Status(1s), DeviceTimeout);
  EXPECT_THROW(gripper.Activate(1s), DeviceTimeout);
  fake.SetMute(false);
  gripper.Activate(2s);  // recovers once the gripper answers again
  EXPECT_TRUE(gripper.Status(1s).activated);
}

TEST(Robotiq2F85, ALostRequestIsSentAgainWithinTheCallsTimeout) {
  // A noisy RS-485 line loses frames: the fake drops the next two requests (a write and a read, each
  // unanswered for response_timeout 100 ms); the call sends them again and completes.
  RobotiqFake fake;
  fake.SetObjectWidth(0.016);
  Robotiq2F85 gripper(ParamsFor(fake));
  gripper.Activate(2s);
  fake.DropNext(2);
  const auto closed = gripper.Close(0.15, 50.0, 5s);
  EXPECT_EQ(closed.object, GripperObject::kStoppedClosing);
  fake.DropNext(1);
  EXPECT_TRUE(gripper.Status(1s).activated);
  // Silent for longer than the call allows: a DeviceTimeout saying how often it asked.
  fake.SetMute(true);
  try {
    gripper.Status(350ms);
    FAIL() << "expected DeviceTimeout";
  } catch (const DeviceTimeout& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no answer to status read on"), std::string::npos) << what;
    // 350 ms at 100 ms per unanswered try: three on a quiet machine; a loaded one fits two (a CI run
    // beside other work gave "(2 tries)"). At least one resend, and never more than fit.
    std::smatch tries;
    ASSERT_TRUE(std::regex_search(what, tries, std::regex(R"(\((\d+) tries\))"))) << what;
    EXPECT_GE(std::stoi(tries[1].str()), 2) << what;
    EXPECT_LE(std::stoi(tries[1].str()), 4) << what;
  }
}

TEST(Robotiq2F85, AnAnswerThatDoesNotFitTheRequestIsAskedAgain) {
  // A late answer to an earlier, timed-out request arrives where the write's answer should: libmodbus
  // calls it invalid data (EMBBADDATA). The write is sent again and the close completes; a gripper
  // that answers every write so fails the call naming the error and the tries.
  RobotiqFake fake;
  fake.SetObjectWidth(0.016);
  Robotiq2F85 gripper(ParamsFor(fake));
  gripper.Activate(2s);
  fake.AnswerNextWritesWithARead(1);
  EXPECT_EQ(gripper.Close(0.15, 50.0, 5s).object, GripperObject::kStoppedClosing);
  fake.AnswerNextWritesWithARead(1000000);  // more than fit in the call
  try {
    gripper.Open(350ms);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("request write failed on"), std::string::npos) << what;
    EXPECT_NE(what.find("Invalid data"), std::string::npos) << what;
    EXPECT_EQ(what.find("(1 try)"), std::string::npos) << what;
  }
}

TEST(Robotiq2F85, ActivationThatNeverCompletesTimesOut) {
  RobotiqFake::Options o;
  o.activation_time = 10s;
  RobotiqFake fake(o);
  Robotiq2F85 gripper(ParamsFor(fake));
  EXPECT_THROW(gripper.Activate(200ms), DeviceTimeout);
}

TEST(Robotiq2F85, BadDevicePathIsADeviceFault) {
  Robotiq2F85Params p;
  p.device = "/nonexistent/tty";
  EXPECT_THROW(Robotiq2F85 g(p), DeviceFault);
}

}  // namespace
}  // namespace tubepick::devices
