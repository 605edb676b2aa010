#include "devices/virtual/rdt_server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <optional>
#include <thread>

#include "core/common/errors.h"
#include "devices/ati_netft.h"
#include "devices/udp_client.h"
#include "devices/virtual/test/scripted_devices.h"

namespace tubepick::devices {
namespace {

using scripted::ScriptedSensor;
using ::testing::HasSubstr;
using namespace std::chrono_literals;

constexpr Timeout kTimeout{2000};

AtiNetFtParams DriverParams(const RdtServer& server) {
  AtiNetFtParams params;
  params.host = "127.0.0.1";
  params.port = server.port();
  return params;
}

WrenchReading Reading(const Eigen::Vector3d& force, const Eigen::Vector3d& torque, std::uint64_t sequence) {
  WrenchReading reading;
  reading.force = force;
  reading.torque = torque;
  reading.sequence = sequence;
  return reading;
}

std::optional<rdt::Record> NextRecord(UdpClient& udp, std::chrono::milliseconds within) {
  std::uint8_t buf[rdt::kRecordSize + 1];
  const auto got = udp.Receive(buf, UdpClient::Clock::now() + within);
  if (!got || *got != rdt::kRecordSize) return std::nullopt;
  return rdt::DecodeRecord(std::span<const std::uint8_t, rdt::kRecordSize>(buf, rdt::kRecordSize));
}

TEST(RdtServer, DriverReadCarriesTheSensorsWrenchAndSequence) {
  ScriptedSensor sensor;
  sensor.Set(Reading({1.5, -2.25, 9.81}, {0.125, -0.0625, 0.003}, 41));
  std::mutex device_lock;
  RdtServer server(sensor, device_lock);
  AtiNetFt driver(DriverParams(server));

  const WrenchReading reading = driver.Read(kTimeout);
  EXPECT_DOUBLE_EQ(reading.force.x(), 1.5);
  EXPECT_DOUBLE_EQ(reading.force.y(), -2.25);
  EXPECT_DOUBLE_EQ(reading.force.z(), 9.81);
  EXPECT_DOUBLE_EQ(reading.torque.x(), 0.125);
  EXPECT_DOUBLE_EQ(reading.torque.y(), -0.0625);
  EXPECT_DOUBLE_EQ(reading.torque.z(), 0.003);
  EXPECT_EQ(reading.sequence, 42u);  // the sensor's own sequence (41 + 1st read)
  EXPECT_EQ(driver.Read(kTimeout).sequence, 43u);
  EXPECT_EQ(sensor.reads(), 2);
  EXPECT_EQ(server.records_sent(), 2u);
}

TEST(RdtServer, CountsAreRoundedWithTheConfiguredScaling) {
  ScriptedSensor sensor;
  sensor.Set(Reading({1.23456, -0.0004, 0.0}, {0.123456, 0.0, -7.5}, 0));
  std::mutex device_lock;
  RdtServerOptions options;
  options.counts_per_force = 1000.0;
  options.counts_per_torque = 10000.0;
  RdtServer server(sensor, device_lock, options);
  AtiNetFtParams params = DriverParams(server);
  params.counts_per_force = 1000.0;
  params.counts_per_torque = 10000.0;
  AtiNetFt driver(params);

  const WrenchReading reading = driver.Read(kTimeout);
  EXPECT_DOUBLE_EQ(reading.force.x(), 1.235);  // 1234.56 counts → 1235
  EXPECT_DOUBLE_EQ(reading.force.y(), 0.0);    // −0.4 counts → 0
  EXPECT_DOUBLE_EQ(reading.torque.x(), 0.1235);
  EXPECT_DOUBLE_EQ(reading.torque.z(), -7.5);
  EXPECT_EQ(reading.sequence, 1u);  // no sensor sequence: the server counts
}

TEST(RdtServer, SensorFaultIsARecordWithAnErrorStatusWord) {
  ScriptedSensor sensor;
  sensor.SetMode(ScriptedSensor::Mode::kFault);
  std::mutex device_lock;
  RdtServer server(sensor, device_lock);
  AtiNetFt driver(DriverParams(server));
  try {
    driver.Read(kTimeout);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("status word 0x80000000"));
  }
  sensor.SetMode(ScriptedSensor::Mode::kAnswer);
  sensor.Set(Reading({0.0, 0.0, 2.0}, {0.0, 0.0, 0.0}, 0));
  EXPECT_DOUBLE_EQ(driver.Read(kTimeout).force.z(), 2.0);
}

TEST(RdtServer, SilentSensorIsADriverTimeout) {
  ScriptedSensor sensor;
  sensor.SetMode(ScriptedSensor::Mode::kTimeout);
  std::mutex device_lock;
  RdtServer server(sensor, device_lock);
  AtiNetFt driver(DriverParams(server));
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(driver.Read(Timeout(150)), DeviceTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 150ms);
  EXPECT_EQ(sensor.reads(), 1);
  EXPECT_EQ(server.records_sent(), 0u);
}

TEST(RdtServer, BiasReachesTheSensor) {
  ScriptedSensor sensor;
  std::mutex device_lock;
  RdtServer server(sensor, device_lock);
  AtiNetFt driver(DriverParams(server));
  driver.Bias(kTimeout);
  for (int i = 0; i < 200 && sensor.biases() == 0; ++i) std::this_thread::sleep_for(5ms);
  EXPECT_EQ(sensor.biases(), 1);
  EXPECT_EQ(sensor.reads(), 0);
}

TEST(RdtServer, ReadsWaitForTheDeviceLock) {
  ScriptedSensor sensor;
  sensor.Set(Reading({0.0, 1.0, 0.0}, {0.0, 0.0, 0.0}, 0));
  std::mutex device_lock;
  RdtServer server(sensor, device_lock);
  AtiNetFt driver(DriverParams(server));
  {
    std::lock_guard held(device_lock);  // another device's call
    EXPECT_THROW(driver.Read(Timeout(150)), DeviceTimeout);
    EXPECT_EQ(sensor.reads(), 0);
  }
  EXPECT_DOUBLE_EQ(driver.Read(kTimeout).force.y(), 1.0);
}

TEST(RdtServer, StreamsTheAskedNumberOfRecordsAndStopsOnRequest) {
  ScriptedSensor sensor;
  sensor.Set(Reading({0.0, 0.0, 1.0}, {0.0, 0.0, 0.0}, 100));
  std::mutex device_lock;
  RdtServer server(sensor, device_lock);
  UdpClient udp("127.0.0.1", server.port(), "test");

  udp.Send(rdt::EncodeRequest(rdt::Command::kStartRealtime, 5), UdpClient::Clock::now() + 1s);
  for (std::uint32_t i = 1; i <= 5; ++i) {
    const auto record = NextRecord(udp, 1s);
    ASSERT_TRUE(record.has_value()) << "record " << i;
    EXPECT_EQ(record->rdt_sequence, i);
    EXPECT_EQ(record->ft_sequence, 100 + i);
    EXPECT_EQ(record->status, 0u);
    EXPECT_EQ(record->counts[2], 1'000'000);
  }
  EXPECT_FALSE(NextRecord(udp, 100ms).has_value());

  // sample_count 0 (stream until stopped): one record, the driver never streams.
  udp.Send(rdt::EncodeRequest(rdt::Command::kStartRealtime, 0), UdpClient::Clock::now() + 1s);
  const auto one = NextRecord(udp, 1s);
  ASSERT_TRUE(one.has_value());
  EXPECT_EQ(one->rdt_sequence, 1u);
  EXPECT_FALSE(NextRecord(udp, 100ms).has_value());

  // A long stream ends on stop.
  sensor.read_time = std::chrono::milliseconds(2);
  udp.Send(rdt::EncodeRequest(rdt::Command::kStartRealtime, 1'000'000), UdpClient::Clock::now() + 1s);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(NextRecord(udp, 1s).has_value());
  udp.Send(rdt::EncodeRequest(rdt::Command::kStopStreaming, 0), UdpClient::Clock::now() + 1s);
  while (NextRecord(udp, 100ms).has_value()) {
  }
  const std::uint64_t sent = server.records_sent();
  EXPECT_LT(sent, 200u);
  EXPECT_FALSE(NextRecord(udp, 100ms).has_value());
  EXPECT_EQ(server.records_sent(), sent);
}

TEST(RdtServer, BadOptionsAreInvalidArgumentsNamingThem) {
  ScriptedSensor sensor;
  std::mutex device_lock;
  RdtServerOptions options;
  options.counts_per_torque = 0.0;
  try {
    RdtServer server(sensor, device_lock, options);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("counts_per_torque"));
  }
}

}  // namespace
}  // namespace tubepick::devices
