#include "devices/exec_scanner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"

namespace tubepick::devices {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using ::testing::HasSubstr;

struct Dir {
  Dir() {
    std::random_device rd;
    path = fs::temp_directory_path() / ("tubepick_exec_" + std::to_string(rd()));
    fs::create_directories(path);
  }
  ~Dir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  fs::path path;
};

ExecScannerParams Params(const Dir& dir, const std::string& command) {
  ExecScannerParams params;
  params.command = command;
  params.work_dir = (dir.path / "work").string();
  fs::create_directories(params.work_dir);
  params.sensor.unit = LengthUnit::kMillimetre;
  params.sensor.X_BinSensor = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.1, 1.0));
  return params;
}

TEST(ExecScanner, RunsTheCommandReadsItsFileAndRemovesIt) {
  Dir dir;
  const Points cloud{{1.0f, 2.0f, 3.0f}, {4.0f, 5.0f, 6.0f}, {7.0f, 8.0f, 900.0f}};
  const std::string source = (dir.path / "recorded.ply").string();
  WritePly(source, cloud);
  // The "vendor tool" copies a recorded capture to the path it is given.
  ExecScanner scanner(Params(dir, "cp '" + source + "' {out}"));
  for (int scan = 0; scan < 2; ++scan) {
    const Capture capture = scanner.Scan(5000ms);
    ASSERT_EQ(capture.points_Sensor.size(), 3u);
    EXPECT_FLOAT_EQ(capture.points_Sensor[2].z(), 900.0f);
    EXPECT_EQ(capture.unit, LengthUnit::kMillimetre);
    EXPECT_NEAR(capture.X_BinSensor.translation().y(), 0.1, 1e-12);
  }
  EXPECT_TRUE(fs::is_empty(dir.path / "work")) << "scan files and stderr captures are removed once read";
}

TEST(ExecScanner, ANonZeroExitIsAFaultWithTheStatusAndTheLastStderrLine) {
  Dir dir;
  ExecScanner scanner(Params(dir, "echo 'camera 192.168.1.20 not found' >&2; exit 7 # {out}"));
  try {
    scanner.Scan(5000ms);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("exit status 7"));
    EXPECT_THAT(e.what(), HasSubstr("camera 192.168.1.20 not found"));
  }
}

TEST(ExecScanner, ACommandThatWritesNoFileOrNotACloudIsAFault) {
  Dir dir;
  ExecScanner none(Params(dir, "true {out}"));
  EXPECT_THROW(
      {
        try {
          none.Scan(5000ms);
        } catch (const DeviceFault& e) {
          EXPECT_THAT(e.what(), HasSubstr("wrote no file"));
          throw;
        }
      },
      DeviceFault);
  ExecScanner garbage(Params(dir, "echo hello > {out}"));
  EXPECT_THROW(garbage.Scan(5000ms), DeviceFault);
}

TEST(ExecScanner, ACommandPastTheTimeoutIsKilledWithItsChildren) {
  Dir dir;
  const fs::path marker = dir.path / "child-survived";
  // The shell starts a child that would write the marker after 1 s: killing the group stops it.
  ExecScanner scanner(Params(dir, "(sleep 1; touch '" + marker.string() + "') & sleep 30; true {out}"));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(scanner.Scan(200ms), DeviceTimeout);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 2s);
  std::this_thread::sleep_for(1500ms);
  EXPECT_FALSE(fs::exists(marker));
}

TEST(ExecScanner, OutPathsWithQuotesAndSpacesAreQuotedForTheShell) {
  Dir dir;
  ExecScanner scanner(Params(dir, "capture --to {out}"));
  EXPECT_EQ(scanner.CommandFor("/tmp/it's a scan.ply"), "capture --to '/tmp/it'\\''s a scan.ply'");
}

TEST(ExecScanner, ACommandWithoutOutIsRefused) {
  Dir dir;
  EXPECT_THROW(ExecScanner(Params(dir, "capture --to /tmp/x.ply")), InvalidArgument);
}

}  // namespace
}  // namespace tubepick::devices
