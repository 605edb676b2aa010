#include "devices/file_replay_scanner.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"

namespace tubepick::devices {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using ::testing::HasSubstr;

class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ =
        fs::temp_directory_path() / ("tubepick_replay_" + std::to_string(rd()) + "_" + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  std::string str() const { return path_.string(); }

 private:
  fs::path path_;
};

Points Cloud(int n, float offset) {
  Points points;
  for (int i = 0; i < n; ++i)
    points.emplace_back(offset + static_cast<float>(i), 0.5f * static_cast<float>(i), -1.0f);
  return points;
}

// scan1.ply (1 point), scan2.pcd (2 points), scan10.ply (3 points); plus files to be ignored.
void WriteThree(const TempDir& dir) {
  WritePly((dir.path() / "scan10.ply").string(), Cloud(3, 10.0f));
  WritePly((dir.path() / "scan1.ply").string(), Cloud(1, 1.0f));
  WritePcd((dir.path() / "scan2.pcd").string(), Cloud(2, 2.0f), /*binary=*/false);
  std::ofstream((dir.path() / "notes.txt").string()) << "not a cloud\n";
  fs::create_directories(dir.path() / "sub.ply");
  WritePly((dir.path() / "sub.ply" / "scan0.ply").string(), Cloud(5, 0.0f));
}

SensorConfig TestSensor() {
  SensorConfig sensor;
  sensor.unit = LengthUnit::kMillimetre;
  sensor.X_BinSensor = Eigen::Isometry3d::Identity();
  sensor.X_BinSensor.translate(Eigen::Vector3d(0.1, -0.2, 900.0));
  sensor.X_BinSensor.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  return sensor;
}

FileReplayScannerParams Params(const TempDir& dir, bool loop = false) {
  FileReplayScannerParams params;
  params.directory = dir.str();
  params.sensor = TestSensor();
  params.loop = loop;
  return params;
}

void ExpectCloud(const Capture& capture, int n, float offset) {
  ASSERT_EQ(capture.points_Sensor.size(), static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(capture.points_Sensor[static_cast<std::size_t>(i)].isApprox(
        Cloud(n, offset)[static_cast<std::size_t>(i)]))
        << "point " << i;
  }
}

TEST(NaturalLess, DigitRunsCompareByValue) {
  EXPECT_TRUE(NaturalLess("scan2", "scan10"));
  EXPECT_FALSE(NaturalLess("scan10", "scan2"));
  EXPECT_TRUE(NaturalLess("scan1.ply", "scan2.pcd"));
  EXPECT_TRUE(NaturalLess("a", "b"));
  EXPECT_TRUE(NaturalLess("scan", "scan1"));
  EXPECT_TRUE(NaturalLess("scan2", "scan02"));
  EXPECT_FALSE(NaturalLess("scan2", "scan2"));
  EXPECT_TRUE(NaturalLess("x99999999999999999999999", "x100000000000000000000000"));
}

TEST(FileReplayScanner, ReplaysInNaturalOrderWithUnitAndPose) {
  TempDir dir;
  WriteThree(dir);
  FileReplayScanner scanner(Params(dir));
  ASSERT_EQ(scanner.files().size(), 3u);
  EXPECT_EQ(scanner.remaining(), 3u);
  EXPECT_EQ(scanner.current_file(), "");
  const SensorConfig sensor = TestSensor();

  const char* names[] = {"scan1.ply", "scan2.pcd", "scan10.ply"};
  const int sizes[] = {1, 2, 3};
  const float offsets[] = {1.0f, 2.0f, 10.0f};
  for (int k = 0; k < 3; ++k) {
    const Capture capture = scanner.Scan(100ms);
    EXPECT_EQ(fs::path(scanner.current_file()).filename().string(), names[k]);
    ExpectCloud(capture, sizes[k], offsets[k]);
    EXPECT_EQ(capture.unit, LengthUnit::kMillimetre);
    EXPECT_TRUE(capture.X_BinSensor.isApprox(sensor.X_BinSensor));
    EXPECT_EQ(scanner.remaining(), static_cast<std::size_t>(2 - k));
  }
}

TEST(FileReplayScanner, ThrowsAfterTheLastScanWithoutLoop) {
  TempDir dir;
  WriteThree(dir);
  FileReplayScanner scanner(Params(dir));
  for (int k = 0; k < 3; ++k) scanner.Scan(0ms);
  try {
    scanner.Scan(0ms);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("no more scans in " + dir.str() + " (3 replayed)"));
  }
  EXPECT_THROW(scanner.Scan(0ms), DeviceFault);  // stays exhausted
}

TEST(FileReplayScanner, LoopWrapsToTheFirstFile) {
  TempDir dir;
  WriteThree(dir);
  FileReplayScanner scanner(Params(dir, /*loop=*/true));
  for (int k = 0; k < 3; ++k) scanner.Scan(0ms);
  EXPECT_EQ(scanner.remaining(), 0u);
  ExpectCloud(scanner.Scan(0ms), 1, 1.0f);
  EXPECT_EQ(fs::path(scanner.current_file()).filename().string(), "scan1.ply");
  EXPECT_EQ(scanner.remaining(), 2u);
  ExpectCloud(scanner.Scan(0ms), 2, 2.0f);
  ExpectCloud(scanner.Scan(0ms), 3, 10.0f);
  ExpectCloud(scanner.Scan(0ms), 1, 1.0f);
}

TEST(FileReplayScanner, CorruptFileIsADeviceFaultNamingItAndReplayGoesOn) {
  TempDir dir;
  WriteThree(dir);
  std::ofstream((dir.path() / "scan3.ply").string()) << "ply\nformat garbage\n";
  FileReplayScanner scanner(Params(dir));
  ASSERT_EQ(scanner.files().size(), 4u);
  scanner.Scan(0ms);  // scan1
  scanner.Scan(0ms);  // scan2
  try {
    scanner.Scan(0ms);
    FAIL() << "expected DeviceFault";
  } catch (const DeviceFault& e) {
    EXPECT_THAT(e.what(), HasSubstr("scan3.ply"));
  }
  EXPECT_EQ(fs::path(scanner.current_file()).filename().string(), "scan3.ply");
  ExpectCloud(scanner.Scan(0ms), 3, 10.0f);  // scan10
  EXPECT_EQ(scanner.remaining(), 0u);
}

TEST(FileReplayScanner, EmptyDirectoryIsAnErrorNamingIt) {
  TempDir dir;
  std::ofstream((dir.path() / "readme.txt").string()) << "nothing\n";
  try {
    FileReplayScanner scanner(Params(dir));
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr(dir.str()));
  }
}

TEST(FileReplayScanner, MissingDirectoryIsAnErrorNamingIt) {
  TempDir dir;
  FileReplayScannerParams params = Params(dir);
  params.directory = (dir.path() / "does_not_exist").string();
  try {
    FileReplayScanner scanner(params);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr(params.directory));
  }
}

}  // namespace
}  // namespace tubepick::devices
