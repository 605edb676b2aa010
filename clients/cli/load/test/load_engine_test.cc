// The load engine's pure parts: latency percentiles and the cloud directory reader.
#include "clients/cli/load/load_engine.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"

namespace tubepick::cli {
namespace {

constexpr double kTol = 1e-12;

TEST(LoadEngine, SummarizeLatencyNearestRank) {
  std::vector<double> seconds;
  for (int i = 100; i >= 1; --i) seconds.push_back(i / 100.0);  // 0.01 .. 1.00, reversed
  const LatencySummary s = SummarizeLatency(seconds);
  EXPECT_NEAR(s.min, 0.01, kTol);
  EXPECT_NEAR(s.p50, 0.50, kTol);
  EXPECT_NEAR(s.p90, 0.90, kTol);
  EXPECT_NEAR(s.p95, 0.95, kTol);
  EXPECT_NEAR(s.p99, 0.99, kTol);
  EXPECT_NEAR(s.max, 1.00, kTol);
  EXPECT_NEAR(s.mean, 0.505, kTol);
  const LatencySummary one = SummarizeLatency({0.3});
  EXPECT_EQ(one.p50, 0.3);
  EXPECT_EQ(one.p99, 0.3);
  EXPECT_EQ(SummarizeLatency({}).max, 0.0);
}

TEST(LoadEngine, ReadLoadCloudsFindsPlyAndPcdRecursivelySorted) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "tubepick_load_clouds_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "scene-2");
  std::filesystem::create_directories(dir / "scene-1");
  WritePly((dir / "scene-2" / "cloud.ply").string(), Points(5, Eigen::Vector3f(0.1f, 0.2f, 1.0f)));
  WritePcd((dir / "scene-1" / "cloud.pcd").string(), Points(3, Eigen::Vector3f(0.1f, 0.2f, 1.0f)), true);
  std::ofstream((dir / "notes.txt").string()) << "not a cloud\n";

  const std::vector<LoadCloud> clouds = ReadLoadClouds(dir.string(), v1::LENGTH_UNIT_MILLIMETRE);
  ASSERT_EQ(clouds.size(), 2u);
  EXPECT_NE(clouds[0].name.find("scene-1"), std::string::npos);
  EXPECT_EQ(clouds[0].xyz.size(), 3u * 12u);
  EXPECT_EQ(clouds[1].xyz.size(), 5u * 12u);
  EXPECT_EQ(clouds[1].unit, v1::LENGTH_UNIT_MILLIMETRE);
  std::filesystem::remove_all(dir);

  std::filesystem::create_directories(dir);
  try {
    ReadLoadClouds(dir.string(), v1::LENGTH_UNIT_UNSPECIFIED);
    FAIL() << "an empty directory must throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("no .ply or .pcd"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(LoadEngine, RpcNamesRoundTrip) {
  for (const LoadRpc rpc : {LoadRpc::kPlanPick, LoadRpc::kModelTubes, LoadRpc::kPlanPickStream})
    EXPECT_EQ(ParseLoadRpc(ToString(rpc)), rpc);
  EXPECT_THROW(ParseLoadRpc("planpick"), InvalidArgument);
}

TEST(LoadEngine, RpcListsParseInOrder) {
  const std::vector<LoadRpc> mixed = ParseLoadRpcs("plan,plan-stream");
  ASSERT_EQ(mixed.size(), 2u);
  EXPECT_EQ(mixed[0], LoadRpc::kPlanPick);
  EXPECT_EQ(mixed[1], LoadRpc::kPlanPickStream);
  EXPECT_EQ(ToString(mixed), "plan,plan-stream");
  EXPECT_EQ(ParseLoadRpcs("model"), std::vector<LoadRpc>{LoadRpc::kModelTubes});
  EXPECT_EQ(ParseLoadRpcs("plan,plan").size(), 2u);
  EXPECT_THROW(ParseLoadRpcs(""), InvalidArgument);
  EXPECT_THROW(ParseLoadRpcs("plan,"), InvalidArgument);
  EXPECT_THROW(ParseLoadRpcs("plan,planpick"), InvalidArgument);
}

}  // namespace
}  // namespace tubepick::cli
