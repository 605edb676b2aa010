#include "devices/virtual/netft_http_server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>

#include "core/common/errors.h"
#include "devices/netft_calibration.h"

namespace tubepick::devices {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

TEST(NetFtCalibration, ReadsTheActiveConfigurationFromTheBoxsWebServer) {
  NetFtHttpServer box("127.0.0.1", 0, {1'000'000.0, 1000.0, "N", "N-mm"});
  const NetFtCalibration c = ReadNetFtCalibration("127.0.0.1", box.port(), 2000ms);
  EXPECT_DOUBLE_EQ(c.counts_per_force, 1'000'000.0);
  EXPECT_DOUBLE_EQ(c.counts_per_torque, 1000.0);
  EXPECT_EQ(c.force_unit, "N");
  EXPECT_EQ(c.torque_unit, "N-mm");
  EXPECT_DOUBLE_EQ(c.CountsPerNewton(), 1'000'000.0);
  EXPECT_DOUBLE_EQ(c.CountsPerNewtonMetre(), 1'000'000.0);  // 1000 per N·mm = 1e6 per N·m
}

TEST(NetFtCalibration, ImperialUnitsConvertToNewtonsAndNewtonMetres) {
  const NetFtCalibration c{1'000'000.0, 1'000'000.0, "lbf", "lbf-in"};
  // 1 lbf = 4.448 N: a million counts per lbf is 224809 per N.
  EXPECT_NEAR(c.CountsPerNewton(), 224808.94, 0.01);
  // 1 lbf·in = 0.1130 N·m.
  EXPECT_NEAR(c.CountsPerNewtonMetre(), 8850745.8, 0.1);
  EXPECT_THROW((NetFtCalibration{1.0, 1.0, "stone", "Nm"}.CountsPerNewton()), InvalidArgument);
}

TEST(NetFtCalibration, AMissingOrBadElementIsAFaultNamingIt) {
  EXPECT_THAT(
      [] {
        try {
          ParseNetFtApi2("<netft><cfgcpf>1000000</cfgcpf><scfgfu>N</scfgfu><scfgtu>Nm</scfgtu></netft>");
        } catch (const DeviceFault& e) {
          return std::string(e.what());
        }
        return std::string();
      }(),
      HasSubstr("no <cfgcpt> element"));
  EXPECT_THROW(ParseNetFtApi2("<cfgcpf>-3</cfgcpf><cfgcpt>1</cfgcpt><scfgfu>N</scfgfu><scfgtu>Nm</scfgtu>"),
               DeviceFault);
}

TEST(NetFtCalibration, NoWebServerIsAFaultOrATimeoutNotADefault) {
  std::uint16_t closed = 0;
  {
    NetFtHttpServer gone("127.0.0.1", 0, {1.0, 1.0, "N", "Nm"});
    closed = gone.port();
  }
  EXPECT_THROW(ReadNetFtCalibration("127.0.0.1", closed, 500ms), DeviceFault);
}

}  // namespace
}  // namespace tubepick::devices
