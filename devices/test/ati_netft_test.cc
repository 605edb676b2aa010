#include "devices/ati_netft.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "devices/testing/rdt_fake.h"

namespace tubepick::devices {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

AtiNetFtParams LoopbackParams(const RdtFake& fake) {
  AtiNetFtParams params;
  params.host = "127.0.0.1";
  params.port = fake.port();
  return params;
}

TEST(RdtCodec, RequestIsBigEndianByteByByte) {
  EXPECT_THAT(rdt::EncodeRequest(rdt::Command::kStartRealtime, 1),
              ElementsAre(0x12, 0x34, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01));
  EXPECT_THAT(rdt::EncodeRequest(rdt::Command::kSetSoftwareBias, 0x01020304),
              ElementsAre(0x12, 0x34, 0x00, 0x42, 0x01, 0x02, 0x03, 0x04));
  const rdt::Request back = rdt::DecodeRequest(rdt::EncodeRequest(rdt::Command::kStopStreaming, 0xA0B0C0D0));
  EXPECT_EQ(back.header, 0x1234);
  EXPECT_EQ(back.command, 0x0000);
  EXPECT_EQ(back.sample_count, 0xA0B0C0D0u);
}

TEST(RdtCodec, RecordIsBigEndianByteByByteWithSignedCounts) {
  rdt::Record record;
  record.rdt_sequence = 0x01020304;
  record.ft_sequence = 0x05060708;
  record.status = 0x80000001;
  record.counts = {-2, 1, 0x7FFFFFFF, -0x7FFFFFFF - 1, 256, -256};
  const rdt::RecordBytes bytes = rdt::EncodeRecord(record);
  EXPECT_THAT(bytes, ElementsAre(0x01, 0x02, 0x03, 0x04,  // rdt_sequence
                                 0x05, 0x06, 0x07, 0x08,  // ft_sequence
                                 0x80, 0x00, 0x00, 0x01,  // status
                                 0xFF, 0xFF, 0xFF, 0xFE,  // Fx = -2
                                 0x00, 0x00, 0x00, 0x01,  // Fy = 1
                                 0x7F, 0xFF, 0xFF, 0xFF,  // Fz = INT32_MAX
                                 0x80, 0x00, 0x00, 0x00,  // Tx = INT32_MIN
                                 0x00, 0x00, 0x01, 0x00,  // Ty = 256
                                 0xFF, 0xFF, 0xFF, 0x00)  // Tz = -256
  );
  const rdt::Record back = rdt::DecodeRecord(bytes);
  EXPECT_EQ(back.rdt_sequence, record.rdt_sequence);
  EXPECT_EQ(back.ft_sequence, record.ft_sequence);
  EXPECT_EQ(back.status, record.status);
  EXPECT_EQ(back.counts, record.counts);
}

TEST(AtiNetFt, ReadConvertsCountsWithDefaultScaling) {
  RdtFake fake;
  fake.SetReply({1'500'000, -2'000'000, 9'810'000, 250'000, -125'000, 0});
  AtiNetFt sensor(LoopbackParams(fake));
  const WrenchReading reading = sensor.Read(Timeout(1000));
  EXPECT_DOUBLE_EQ(reading.force.x(), 1.5);
  EXPECT_DOUBLE_EQ(reading.force.y(), -2.0);
  EXPECT_DOUBLE_EQ(reading.force.z(), 9.81);
  EXPECT_DOUBLE_EQ(reading.torque.x(), 0.25);
  EXPECT_DOUBLE_EQ(reading.torque.y(), -0.125);
  EXPECT_DOUBLE_EQ(reading.torque.z(), 0.0);
  EXPECT_EQ(reading.sequence, 1u);
  // The request on the wire: one real-time record.
  ASSERT_EQ(fake.requests().size(), 1u);
  EXPECT_THAT(fake.requests()[0], ElementsAre(0x12, 0x34, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01));
}

TEST(AtiNetFt, ReadUsesSeparateForceAndTorqueScales) {
  RdtFake fake;
  fake.SetReply({1000, 2000, -3000, 500, 1000, -1500});
  AtiNetFtParams params = LoopbackParams(fake);
  params.counts_per_force = 1000.0;  // counts per N
  params.counts_per_torque = 500.0;  // counts per N·m
  AtiNetFt sensor(params);
  const WrenchReading first = sensor.Read(Timeout(1000));
  EXPECT_DOUBLE_EQ(first.force.x(), 1.0);
  EXPECT_DOUBLE_EQ(first.force.y(), 2.0);
  EXPECT_DOUBLE_EQ(first.force.z(), -3.0);
  EXPECT_DOUBLE_EQ(first.torque.x(), 1.0);
  EXPECT_DOUBLE_EQ(first.torque.y(), 2.0);
  EXPECT_DOUBLE_EQ(first.torque.z(), -3.0);
  fake.SetReply({0, 0, 4000, 0, 0, 0});
  const WrenchReading second = sensor.Read(Timeout(1000));
  EXPECT_DOUBLE_EQ(second.force.z(), 4.0);
  EXPECT_EQ(second.sequence, first.sequence + 1);
}

TEST(AtiNetFt, BiasReachesTheFake) {
  RdtFake fake;
  AtiNetFt sensor(LoopbackParams(fake));
  sensor.Bias(Timeout(1000));
  // Bias is not acknowledged; a following Read is answered after the bias was processed.
  sensor.Read(Timeout(1000));
  EXPECT_EQ(fake.bias_count(), 1);
  const auto requests = fake.requests();
  ASSERT_EQ(requests.size(), 2u);
  EXPECT_THAT(requests[0], ElementsAre(0x12, 0x34, 0x00, 0x42, 0x00, 0x00, 0x00, 0x00));
}

TEST(AtiNetFt, SilentSensorTimesOutWithinTheTimeout) {
  RdtFake fake;
  fake.SetSilent(true);
  AtiNetFt sensor(LoopbackParams(fake));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(sensor.Read(Timeout(150)), DeviceTimeout);
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_GE(elapsed, std::chrono::milliseconds(150));
  EXPECT_LT(elapsed, std::chrono::milliseconds(1000));
  // The sensor recovers once the fake answers again.
  fake.SetSilent(false);
  fake.SetReply({1'000'000, 0, 0, 0, 0, 0});
  EXPECT_DOUBLE_EQ(sensor.Read(Timeout(1000)).force.x(), 1.0);
}

TEST(AtiNetFt, NonZeroStatusIsADeviceFaultWithTheStatusInHex) {
  RdtFake fake;
  fake.SetReply({0, 0, 0, 0, 0, 0}, 0x80010002);
  AtiNetFt sensor(LoopbackParams(fake));
  try {
    sensor.Read(Timeout(1000));
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& fault) {
    EXPECT_THAT(std::string(fault.what()), HasSubstr("0x80010002"));
  }
}

TEST(AtiNetFt, NothingListeningIsAFault) {
  std::uint16_t port = 0;
  {
    RdtFake fake;  // reserve an ephemeral port, then free it
    port = fake.port();
  }
  AtiNetFtParams params;
  params.host = "127.0.0.1";
  params.port = port;
  AtiNetFt sensor(params);
  // Loopback answers with ICMP port-unreachable, which the connected socket reports.
  EXPECT_THROW(sensor.Read(Timeout(500)), DeviceFault);
}

TEST(AtiNetFt, RejectsZeroScalingAndUnresolvableHost) {
  AtiNetFtParams params;
  params.host = "127.0.0.1";
  params.counts_per_force = 0.0;
  EXPECT_THROW(AtiNetFt{params}, std::invalid_argument);
  params.counts_per_force = 1.0;
  params.host = "no such host.invalid";
  EXPECT_THROW(AtiNetFt{params}, DeviceFault);
}

}  // namespace
}  // namespace tubepick::devices
